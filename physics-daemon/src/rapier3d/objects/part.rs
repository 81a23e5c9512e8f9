//! What an object is beyond its rapier body: the properties of the API, and how they turn
//! into rapier's collider shape, material, mass properties and locked axes.
//!
//! Shapes and their Size: Cube (a box of Size), Sphere (radius min(Size) / 2), Capsule and
//! Cylinder along the body's Y axis (radius min(Size.X, Size.Z) / 2, total height Size.Y),
//! Wedge (half of the Size box, sloping down toward -Z: see [`wedge_points`]) and Mesh (the
//! convex hull of its vertices, scaled to Size). The body's origin is always the centre of
//! the Size box.

use rapier3d::prelude::*;
use shm_layout::{CollisionGroups, CommandError, ObjectSettings, Shape, ShapeKind, Vec3};

/// Contact skin of a map (triangle mesh): bodies rest 0.005 above it (not visible), and
/// one sliding across it at 20 units/s rides over the seams of its triangles instead of
/// catching their inner edges (it stopped within 60 units without a skin).
const MAP_CONTACT_SKIN: f32 = 0.005;

/// Most points a mesh part's collision hull is built from. Larger vertex sets are reduced
/// to their support points along this many directions first (PhysX likewise caps convex
/// hulls at 255 vertices), so the hull of any accepted mesh costs a bounded, small time and
/// a Size change rescales the reduced set instead of recomputing from every vertex.
pub const MAX_HULL_POINTS: usize = 384;

/// A mesh part: vertices as given, the size they span (Size rescales them), and the points
/// its hull is built from (all vertices, or their support points when there are many).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Mesh {
    vertices: Vec<Vec3>,
    hull_points: Vec<Vec3>,
    extent: Vec3,
}

/// The API-level properties of one object: its shape and size, and the stored settings
/// (defaults and checks defined once in `shm_layout::settings`; read through `Deref`).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Part {
    pub shape: ShapeKind,
    pub size: Vec3,
    pub mesh: Option<Mesh>,
    pub settings: ObjectSettings,
    /// A character controller's capsule (its collider runs the contact hook).
    pub is_controller: bool,
    /// A map object's triangle mesh (see `maps`): static, never reshaped.
    pub map: Option<MapShape>,
    /// Joints that hold this part: a held part rotates whatever its HitBoxQuality (a hinge
    /// of default cubes swings, a motor turns its wheel).
    pub joints: u32,
}

/// A built map's collider shape and what it counts against the mesh quota. A snapshot
/// writes the mesh once, with the map's collider, and this only by its content hash
/// (`map_store`): a restore takes the shape back from the collider.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct MapShape {
    #[serde(skip, default = "unrestored_map")]
    pub shape: SharedShape,
    pub cost: u64,
    /// The mesh's content hash (`map_store::content_hash`).
    pub hash: u64,
}

/// What a decoded map holds until the restore takes its collider's mesh (never stepped).
fn unrestored_map() -> SharedShape {
    SharedShape::ball(0.5)
}

impl std::fmt::Debug for MapShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MapShape({} quota units)", self.cost)
    }
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
            Shape::Cube { size }
            | Shape::Capsule { size }
            | Shape::Cylinder { size }
            | Shape::Wedge { size } => (*size, None),
            Shape::Sphere { radius } => ([2.0 * radius; 3], None),
            Shape::Mesh { vertices, .. } => {
                let extent = extent_of(vertices);
                (
                    extent,
                    Some(Mesh {
                        vertices: vertices.clone(),
                        hull_points: hull_points(vertices),
                        extent,
                    }),
                )
            }
        };
        let mut part = Part {
            shape: shape.kind(),
            size,
            mesh,
            settings: ObjectSettings::default(),
            is_controller: false,
            map: None,
            joints: 0,
        };
        // A wedge's mass sits off its origin: CenterOfMass reads where it is.
        part.settings.center_of_mass = part.natural_center_of_mass();
        part
    }

    /// Changes Size, checking that the shape can be built at it (the part is unchanged on
    /// error). A CenterOfMass that was the shape's own centroid follows the new size; one
    /// set by hand stays.
    pub fn resize(&mut self, size: Vec3) -> Result<(), CommandError> {
        let old = self.size;
        let followed = self.center_of_mass == self.natural_center_of_mass();
        self.size = size;
        if let Err(e) = self.collider_shape() {
            self.size = old;
            return Err(e);
        }
        if followed {
            self.settings.center_of_mass = self.natural_center_of_mass();
        }
        Ok(())
    }

    /// Where the shape's mass centre is when CenterOfMass is left alone: the wedge's
    /// centroid (0, -Size.Y/6, +Size.Z/6), the origin for every other shape (a mesh part's
    /// vertex centroid only through RecalculateCenterOfMass).
    pub fn natural_center_of_mass(&self) -> Vec3 {
        match self.shape {
            ShapeKind::Wedge => wedge_centroid(self.size),
            _ => [0.0; 3],
        }
    }

    /// A map object: an anchored triangle mesh spanning `size`; `cost` counts against the
    /// mesh quota while it lives.
    pub fn map(shape: SharedShape, hash: u64, size: Vec3, cost: u64) -> Part {
        let mut part = Part::new(&Shape::Cube { size });
        part.shape = ShapeKind::TriMesh;
        part.map = Some(MapShape { shape, cost, hash });
        part
    }

    /// Vertices of the part's mesh (0 for primitives; vertices + triangles for a map).
    pub fn mesh_vertex_count(&self) -> usize {
        if let Some(m) = &self.map {
            return m.cost as usize;
        }
        self.mesh.as_ref().map_or(0, |m| m.vertices.len())
    }

    /// The collision shape for the current Size.
    pub fn collider_shape(&self) -> Result<SharedShape, CommandError> {
        let [x, y, z] = self.size;
        if let Some(m) = &self.map {
            return Ok(m.shape.clone());
        }
        Ok(match (&self.mesh, self.shape) {
            (_, ShapeKind::Cube) => SharedShape::cuboid(x / 2.0, y / 2.0, z / 2.0),
            (_, ShapeKind::Sphere) => SharedShape::ball(x.min(y).min(z) / 2.0),
            (_, ShapeKind::Capsule) => {
                let radius = x.min(z) / 2.0;
                let half_segment = y / 2.0 - radius;
                if half_segment > 0.0 {
                    SharedShape::capsule_y(half_segment, radius)
                } else {
                    // No taller than its diameter: only the two caps remain, a ball.
                    SharedShape::ball(radius)
                }
            }
            (_, ShapeKind::Cylinder) => SharedShape::cylinder(y / 2.0, x.min(z) / 2.0),
            // The convex hull of its 6 corners, whose faces are known: handing them over
            // skips the hull search, which fails on accepted extremes such as
            // 0.001 × 0.001 × 100,000 (f32 cannot tell those corners apart from coplanar).
            (_, ShapeKind::Wedge) => {
                SharedShape::convex_mesh(wedge_points(self.size).to_vec(), &WEDGE_FACES)
                    .ok_or_else(|| {
                        CommandError::invalid_field(
                            "Size",
                            format!("a Wedge of Size {:?} spans no volume", self.size),
                        )
                    })?
            }
            (Some(mesh), ShapeKind::Mesh) => {
                let points = mesh.scaled_hull_points(self.size);
                let flat = || {
                    CommandError::invalid(format!(
                        "Mesh vertices span no volume (all coplanar?) at Size {:?}",
                        self.size
                    ))
                };
                let hull = SharedShape::convex_hull(&points).ok_or_else(flat)?;
                // A coplanar point set still yields a (flat) hull: it has no mass or inertia.
                // Flat relative to the part's own box, so tiny meshes are not refused.
                if hull.mass_properties(1.0).mass() <= 1e-6 * x * y * z {
                    return Err(flat());
                }
                hull
            }
            (None, ShapeKind::Mesh) | (_, ShapeKind::TriMesh) => {
                unreachable!("mesh parts carry their mesh, maps their triangle mesh")
            }
        })
    }

    /// What RecalculateCenterOfMass writes (body-local, at the current Size): a mesh part's
    /// vertex centroid, a wedge's centroid; `None` for the symmetric primitives, whose
    /// centroid is the origin and who carry no vertices (the call leaves them unchanged).
    pub fn centroid(&self) -> Option<Vec3> {
        if self.shape == ShapeKind::Wedge {
            return Some(wedge_centroid(self.size));
        }
        let points = self.mesh.as_ref()?.scaled(self.size);
        let n = points.len() as f32;
        let sum = points.iter().fold(Vector::ZERO, |a, p| a + *p);
        Some((sum / n).into())
    }

    /// Low-quality non-spheres (capsules and cylinders included) without a CenterOfMass
    /// offset translate but do not spin from contacts (the documented HitBoxQuality
    /// behaviour), unless a joint holds them. A wedge's own off-centre centroid is not an
    /// offset: only a CenterOfMass moved away from it frees its rotation.
    pub fn rotation_locked_by_quality(&self) -> bool {
        self.hit_box_quality < 2
            && self.joints == 0
            && self.shape != ShapeKind::Sphere
            && self.center_of_mass == self.natural_center_of_mass()
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

    /// Which colliders this part's collider meets: none without CanCollide, else those whose
    /// collision group collides with its group in `groups`.
    pub fn interaction_groups(&self, groups: &CollisionGroups) -> InteractionGroups {
        if !self.can_collide {
            return InteractionGroups::none();
        }
        let g = self.collision_group;
        InteractionGroups::new(
            Group::from_bits_retain(1 << g),
            Group::from_bits_retain(groups.mask(g)),
            InteractionTestMode::And,
        )
    }

    /// Writes shape, material, collision groups and mass properties into `collider`.
    pub fn configure_collider(
        &self,
        collider: &mut Collider,
        groups: &CollisionGroups,
    ) -> Result<(), CommandError> {
        collider.set_shape(self.collider_shape()?);
        // Rapier has no geometric-mean rule: storing sqrt(μ) and multiplying gives sqrt(a·b).
        collider.set_friction(self.friction.sqrt());
        collider.set_friction_combine_rule(CoefficientCombineRule::Multiply);
        collider.set_restitution(self.bounciness);
        collider.set_restitution_combine_rule(CoefficientCombineRule::Max);
        // No contact skin: resting bodies touch. A skin of 0.01 per collider kept every
        // resting pair 0.02 apart, visibly, and with soft CCD (see `solver`) a pair moving
        // along such a gap loses its contact. Stacks and piles stand as well without it.
        // Maps keep [`MAP_CONTACT_SKIN`]: a box sliding over a triangle mesh without one
        // catches the triangles' inner edges.
        collider.set_contact_skin(if self.map.is_some() {
            MAP_CONTACT_SKIN
        } else {
            0.0
        });
        collider.set_collision_groups(self.interaction_groups(groups));
        // The rest-threshold hook only matters where something can bounce; a controller's
        // capsule needs it for its capped pushes.
        let hooks = if self.bounciness > 0.0 || self.is_controller {
            ActiveHooks::MODIFY_SOLVER_CONTACTS
        } else {
            ActiveHooks::empty()
        };
        // A body thinner than rapier's contact-recycling window: its contacts are recomputed
        // every step (see `thin`).
        let opt_out = crate::rapier3d::contacts::thin::recycling_opt_out(
            collider.shape(),
            self.map.is_some(),
        );
        collider.set_active_hooks(hooks | opt_out);
        collider.set_active_events(if self.report_contacts {
            ActiveEvents::COLLISION_EVENTS
        } else {
            ActiveEvents::empty()
        });
        if self.map.is_some() {
            // Static: a surface mesh has no volume to take a mass from.
            return Ok(());
        }
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
        // Rapier's own angular cap (a quarter turn per tick) is switched off: the plane's
        // MaxAngularSpeed is the one limit (see `limits`).
        body.set_allow_fast_rotation(true);
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
    fn scale(&self, size: Vec3) -> Vector {
        Vector::from(size) / Vector::from(self.extent).max(Vector::splat(1e-12))
    }

    fn scaled(&self, size: Vec3) -> Vec<Vector> {
        let scale = self.scale(size);
        self.vertices
            .iter()
            .map(|v| Vector::from(*v) * scale)
            .collect()
    }

    /// The hull's input points at `size`. A diagonal scale maps the support points of the
    /// unscaled set onto support points of the scaled set, so rescaling the reduced set is
    /// exact for the hull it spans.
    fn scaled_hull_points(&self, size: Vec3) -> Vec<Vector> {
        let scale = self.scale(size);
        self.hull_points
            .iter()
            .map(|v| Vector::from(*v) * scale)
            .collect()
    }
}

/// `vertices` when there are at most [`MAX_HULL_POINTS`], else their support points along
/// [`MAX_HULL_POINTS`] directions spread evenly over the sphere (a Fibonacci lattice), the
/// extremes along the axes included: the hull of these points is inscribed in the true hull
/// and touches it in every sampled direction.
fn hull_points(vertices: &[Vec3]) -> Vec<Vec3> {
    if vertices.len() <= MAX_HULL_POINTS {
        return vertices.to_vec();
    }
    let axes = [
        Vector::X,
        Vector::NEG_X,
        Vector::Y,
        Vector::NEG_Y,
        Vector::Z,
        Vector::NEG_Z,
    ];
    let n = MAX_HULL_POINTS - axes.len();
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let directions = axes.into_iter().chain((0..n).map(|i| {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let t = golden * i as f32;
        Vector::new(r * t.cos(), y, r * t.sin())
    }));
    let mut picked: Vec<usize> = directions
        .map(|d| {
            let mut best = (f32::NEG_INFINITY, 0);
            for (i, v) in vertices.iter().enumerate() {
                let s = d.dot(Vector::from(*v));
                if s > best.0 {
                    best = (s, i);
                }
            }
            best.1
        })
        .collect();
    picked.sort_unstable();
    picked.dedup();
    picked.into_iter().map(|i| vertices[i]).collect()
}

/// The 6 corners of a wedge filling half of its `size` box (origin at the box centre), as
/// Roblox's WedgePart: the bottom face (y = -Y/2) is full, the vertical face is the back
/// (z = +Z/2), and the slope runs from the top-back edge (y = +Y/2, z = +Z/2) down to the
/// bottom-front edge (y = -Y/2, z = -Z/2). Cross-section in YZ: (-Y/2, -Z/2), (-Y/2, +Z/2),
/// (+Y/2, +Z/2), extruded over X.
fn wedge_points(size: Vec3) -> [Vector; 6] {
    let [hx, hy, hz] = size.map(|c| c / 2.0);
    let section = [(-hy, -hz), (-hy, hz), (hy, hz)];
    std::array::from_fn(|i| {
        let (y, z) = section[i % 3];
        Vector::new(if i < 3 { -hx } else { hx }, y, z)
    })
}

/// The faces of [`wedge_points`] as outward (counter-clockwise) triangles: the two ends
/// (-X, +X), the bottom (-Y), the back (+Z) and the slope.
const WEDGE_FACES: [[u32; 3]; 8] = [
    [0, 1, 2],
    [3, 5, 4],
    [0, 3, 4],
    [0, 4, 1],
    [1, 4, 5],
    [1, 5, 2],
    [0, 2, 5],
    [0, 5, 3],
];

/// Centroid of the wedge of `size` (that of its right-triangle cross-section):
/// (0, -Y/6, +Z/6).
fn wedge_centroid(size: Vec3) -> Vec3 {
    [0.0, -size[1] / 6.0, size[2] / 6.0]
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` points on a unit sphere (a Fibonacci lattice).
    fn sphere(n: usize) -> Vec<Vec3> {
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        (0..n)
            .map(|i| {
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - y * y).sqrt();
                let t = golden * i as f32;
                [r * t.cos(), y, r * t.sin()]
            })
            .collect()
    }

    #[test]
    fn a_large_point_sphere_gets_a_bounded_correct_hull() {
        let part = Part::new(&Shape::Mesh {
            vertices: sphere(65_536),
            triangles: vec![],
        });
        let hull = part
            .collider_shape()
            .expect("a sphere of points is a solid");
        let volume = hull.mass_properties(1.0).mass();
        let exact = 4.0 / 3.0 * std::f32::consts::PI;
        // An inscribed polytope of ~380 support points holds > 97 % of the ball's volume.
        assert!(volume < exact && volume > 0.97 * exact, "volume {volume}");
        assert!(part.mesh.as_ref().unwrap().hull_points.len() <= MAX_HULL_POINTS);
        // Rescaling reuses the reduced set, and the rescaled hull is the scaled ball.
        let mut part = part;
        part.size = [4.0, 2.0, 2.0];
        let stretched = part.collider_shape().unwrap().mass_properties(1.0).mass();
        assert!(
            (stretched / volume - 2.0).abs() < 1e-3,
            "{stretched} vs 2 × {volume}"
        );
    }

    #[test]
    fn new_shapes_have_their_closed_form_volumes_and_centroids() {
        use std::f32::consts::PI;
        let volume = |shape: Shape| {
            let part = Part::new(&shape);
            let props = part.collider_shape().unwrap().mass_properties(1.0);
            (props.mass(), props.local_com, part)
        };
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * b.abs().max(1.0);
        // Capsule: r = min(X, Z)/2 = 0.5, segment h = Y - 2r = 2.
        let (v, com, _) = volume(Shape::Capsule {
            size: [1.0, 3.0, 1.5],
        });
        assert!(close(v, PI * 0.25 * (2.0 + 4.0 * 0.5 / 3.0)), "{v}");
        assert!(com.length() < 1e-6);
        // A capsule no taller than its diameter is the ball.
        let (v, _, _) = volume(Shape::Capsule {
            size: [2.0, 1.5, 2.0],
        });
        assert!(close(v, 4.0 / 3.0 * PI), "{v}");
        // Cylinder: π r² h.
        let (v, _, _) = volume(Shape::Cylinder {
            size: [2.0, 3.0, 4.0],
        });
        assert!(close(v, PI * 3.0), "{v}");
        // Wedge: half the box, centroid (0, -Y/6, Z/6), which CenterOfMass reads.
        let (v, com, part) = volume(Shape::Wedge {
            size: [2.0, 3.0, 4.0],
        });
        assert!(close(v, 12.0), "{v}");
        assert!(
            (com - Vector::new(0.0, -0.5, 4.0 / 6.0)).length() < 1e-5,
            "{com:?}"
        );
        assert_eq!(part.center_of_mass, [0.0, -0.5, 4.0 / 6.0]);
        assert!(
            part.rotation_locked_by_quality(),
            "its own centroid is no offset"
        );
        // The slope falls toward -Z: the top at the back, nothing at the front top.
        let hull = part.collider_shape().unwrap();
        let top_back = Vector::new(0.0, 1.49, 1.99);
        let top_front = Vector::new(0.0, 1.49, -1.99);
        let at = rapier3d::math::Pose::IDENTITY;
        assert!(hull.contains_point(&at, top_back));
        assert!(!hull.contains_point(&at, top_front));
    }

    #[test]
    fn extreme_accepted_sizes_build_every_new_shape() {
        use shm_layout::validate::{MAX_SIZE, MIN_SIZE};
        let extremes = [MIN_SIZE, 1.0, MAX_SIZE];
        for x in extremes {
            for y in extremes {
                for z in extremes {
                    let size = [x, y, z];
                    for shape in [
                        Shape::Capsule { size },
                        Shape::Cylinder { size },
                        Shape::Wedge { size },
                    ] {
                        let part = Part::new(&shape);
                        let props = part.collider_shape().unwrap().mass_properties(1.0);
                        assert!(props.mass() > 0.0 && props.mass().is_finite(), "{shape:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_wedge_centre_of_mass_follows_size_unless_set_by_hand() {
        let mut part = Part::new(&Shape::Wedge { size: [1.0; 3] });
        part.resize([1.0, 6.0, 6.0]).unwrap();
        assert_eq!(part.center_of_mass, [0.0, -1.0, 1.0]);
        part.settings.center_of_mass = [0.0; 3];
        part.resize([1.0, 3.0, 3.0]).unwrap();
        assert_eq!(part.center_of_mass, [0.0; 3]);
        assert!(!part.rotation_locked_by_quality(), "moved off its centroid");
    }

    #[test]
    fn flat_point_sets_are_refused_and_tiny_solids_are_not() {
        let flat = Part::new(&Shape::Mesh {
            vertices: (0..1000)
                .map(|i| [(i % 10) as f32, (i / 10) as f32, 0.0])
                .collect(),
            triangles: vec![],
        });
        assert!(flat.collider_shape().is_err());
        let tiny = Part::new(&Shape::Mesh {
            vertices: sphere(100).iter().map(|v| v.map(|c| c * 1e-3)).collect(),
            triangles: vec![],
        });
        assert!(tiny.collider_shape().is_ok());
    }
}
