//! What an object is beyond its rapier body: the properties of the API, and how they turn
//! into rapier's collider shape, material, mass properties and locked axes.

use rapier3d::prelude::*;
use shm_layout::{CommandError, ObjectSettings, Shape, ShapeKind, Vec3};

/// Contact skin of one collider at HitBoxQuality 1 (a pair of them keeps 0.02 apart); it
/// shrinks as 1 / quality.
const BASE_CONTACT_SKIN: f32 = 0.01;

/// A mesh part: vertices as given, and the size they span (Size rescales them).
#[derive(Debug)]
pub(super) struct Mesh {
    vertices: Vec<Vec3>,
    extent: Vec3,
}

/// The API-level properties of one object: its shape and size, and the stored settings
/// (defaults and checks defined once in `shm_layout::settings`; read through `Deref`).
#[derive(Debug)]
pub(super) struct Part {
    pub shape: ShapeKind,
    pub size: Vec3,
    pub mesh: Option<Mesh>,
    pub settings: ObjectSettings,
    /// The tick whose force pass already handled this object (avoids doing it twice).
    pub forced_tick: u64,
}

impl std::ops::Deref for Part {
    type Target = ObjectSettings;
    fn deref(&self) -> &ObjectSettings {
        &self.settings
    }
}

impl std::ops::DerefMut for Part {
    fn deref_mut(&mut self) -> &mut ObjectSettings {
        &mut self.settings
    }
}

impl Part {
    pub fn new(shape: &Shape) -> Part {
        let (size, mesh) = match shape {
            Shape::Cube { size } => (*size, None),
            Shape::Sphere { radius } => ([2.0 * radius; 3], None),
            Shape::Mesh { vertices, .. } => {
                let extent = extent_of(vertices);
                (
                    extent,
                    Some(Mesh {
                        vertices: vertices.clone(),
                        extent,
                    }),
                )
            }
        };
        Part {
            shape: shape.kind(),
            size,
            mesh,
            settings: ObjectSettings::default(),
            forced_tick: 0,
        }
    }

    /// Vertices of the part's mesh (0 for primitives).
    pub fn mesh_vertex_count(&self) -> usize {
        self.mesh.as_ref().map_or(0, |m| m.vertices.len())
    }

    /// The collision shape for the current Size.
    pub fn collider_shape(&self) -> Result<SharedShape, CommandError> {
        let [x, y, z] = self.size;
        Ok(match (&self.mesh, self.shape) {
            (_, ShapeKind::Cube) => SharedShape::cuboid(x / 2.0, y / 2.0, z / 2.0),
            (_, ShapeKind::Sphere) => SharedShape::ball(x.min(y).min(z) / 2.0),
            (Some(mesh), ShapeKind::Mesh) => {
                let points = mesh.scaled(self.size);
                let flat = || {
                    CommandError::invalid(format!(
                        "Mesh vertices span no volume (all coplanar?) at Size {:?}",
                        self.size
                    ))
                };
                let hull = SharedShape::convex_hull(&points).ok_or_else(flat)?;
                // A coplanar point set still yields a (flat) hull: it has no mass or inertia.
                if hull.mass_properties(1.0).mass() <= 1e-9 {
                    return Err(flat());
                }
                hull
            }
            (None, ShapeKind::Mesh) => unreachable!("mesh parts always carry their mesh"),
        })
    }

    /// Vertex centroid of the mesh at the current Size (body-local), if the part has one.
    pub fn mesh_centroid(&self) -> Option<Vec3> {
        let points = self.mesh.as_ref()?.scaled(self.size);
        let n = points.len() as f32;
        let sum = points.iter().fold(Vector::ZERO, |a, p| a + *p);
        Some((sum / n).into())
    }

    /// Low-quality non-spheres without a centre of mass translate but do not spin from
    /// contacts (the documented HitBoxQuality behaviour).
    pub fn rotation_locked_by_quality(&self) -> bool {
        self.hit_box_quality < 2
            && self.shape != ShapeKind::Sphere
            && self.center_of_mass == [0.0; 3]
    }

    pub fn locked_axes(&self) -> LockedAxes {
        let bits = [
            LockedAxes::TRANSLATION_LOCKED_X,
            LockedAxes::TRANSLATION_LOCKED_Y,
            LockedAxes::TRANSLATION_LOCKED_Z,
            LockedAxes::ROTATION_LOCKED_X,
            LockedAxes::ROTATION_LOCKED_Y,
            LockedAxes::ROTATION_LOCKED_Z,
        ];
        let mut axes = LockedAxes::empty();
        for (locked, bit) in self.locks.iter().zip(bits) {
            if *locked {
                axes |= bit;
            }
        }
        if self.rotation_locked_by_quality() {
            axes |= LockedAxes::ROTATION_LOCKED;
        }
        axes
    }

    /// Mass in effect: Density × volume when Density is set, Weight otherwise.
    pub fn mass(&self, volume: f32) -> f32 {
        if self.density > 0.0 {
            (self.density * volume).max(shm_layout::validate::MIN_MASS)
        } else {
            self.weight
        }
    }

    /// Writes shape, material and mass properties into `collider`.
    pub fn configure_collider(&self, collider: &mut Collider) -> Result<(), CommandError> {
        collider.set_shape(self.collider_shape()?);
        // Rapier has no geometric-mean rule: storing sqrt(μ) and multiplying gives sqrt(a·b).
        collider.set_friction(self.friction.sqrt());
        collider.set_friction_combine_rule(CoefficientCombineRule::Multiply);
        collider.set_restitution(self.bounciness);
        collider.set_restitution_combine_rule(CoefficientCombineRule::Max);
        collider.set_contact_skin(BASE_CONTACT_SKIN / self.hit_box_quality as f32);
        collider.set_collision_groups(if self.can_collide {
            InteractionGroups::all()
        } else {
            InteractionGroups::none()
        });
        // The rest-threshold hook only matters where something can bounce.
        collider.set_active_hooks(if self.bounciness > 0.0 {
            ActiveHooks::MODIFY_SOLVER_CONTACTS
        } else {
            ActiveHooks::empty()
        });
        collider.set_active_events(if self.report_contacts {
            ActiveEvents::COLLISION_EVENTS
        } else {
            ActiveEvents::empty()
        });
        let unit = collider.shape().mass_properties(1.0);
        let volume = unit.mass();
        let mass = self.mass(volume);
        let mut props = collider.shape().mass_properties(mass / volume);
        props.local_com = Vector::from(self.center_of_mass);
        collider.set_mass_properties(props);
        Ok(())
    }

    /// Writes locks and CCD into `body` and refreshes its mass from `colliders`.
    pub fn configure_body(&self, body: &mut RigidBody, colliders: &ColliderSet) {
        body.set_locked_axes(self.locked_axes(), true);
        body.enable_ccd(self.hit_box_quality > 1);
        body.recompute_mass_properties_from_colliders(colliders);
        // Zero the velocity along newly locked axes so a lock holds the current value.
        let mut v = body.linvel();
        let mut w = body.angvel();
        for i in 0..3 {
            if self.locks[i] {
                v[i] = 0.0;
            }
            if self.locks[i + 3] {
                w[i] = 0.0;
            }
        }
        body.set_linvel(v, false);
        body.set_angvel(w, false);
    }
}

impl Mesh {
    fn scaled(&self, size: Vec3) -> Vec<Vector> {
        let scale = Vector::from(size) / Vector::from(self.extent).max(Vector::splat(1e-12));
        self.vertices
            .iter()
            .map(|v| Vector::from(*v) * scale)
            .collect()
    }
}

fn extent_of(vertices: &[Vec3]) -> Vec3 {
    let mut lo = Vector::splat(f32::INFINITY);
    let mut hi = Vector::splat(f32::NEG_INFINITY);
    for v in vertices {
        lo = lo.min(Vector::from(*v));
        hi = hi.max(Vector::from(*v));
    }
    (hi - lo).into()
}
