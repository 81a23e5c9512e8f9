//! Triangle-mesh maps and props from glTF 2.0 files (.glb, or .gltf with embedded data).
//!
//! The client reads and parses the file (the daemon never opens a file for a client); every
//! mesh node of the default scene is taken with its node transforms. A map is uploaded in
//! pieces of at most [`MAX_PIECE`] vertices + triangles (each within the daemon's
//! per-object mesh quota, all of them counting against the per-client one) and built by the
//! daemon in one op: the whole map or nothing. A prop is one dynamic object: the convex hull
//! of the file's vertices, or with `decompose` a convex decomposition whose hulls become
//! objects welded by Fixed joints.

use shm_layout::geometry::rotate;
use std::path::Path;

use gltf::json;
use shm_layout::map_op::MAX_PIECE;
use shm_layout::{
    Command, JointKind, MapOp, MapReport, ObjectProp, PlaneOp, Pose, Reply, Shape, Vec3,
};

use crate::{error::Error, object::Object, plane::Plane};

/// One mesh in map space (node transforms applied).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MapMesh {
    /// Vertices.
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// Where a map goes: `Position` / `Rotation` / `Scale` of `LoadMap`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapOptions {
    /// Pose of the map's origin.
    pub pose: Pose,
    /// Per-axis scale applied to the file's coordinates first.
    pub scale: Vec3,
}

impl Default for MapOptions {
    fn default() -> Self {
        MapOptions {
            pose: Pose::IDENTITY,
            scale: [1.0; 3],
        }
    }
}

/// A loaded map.
#[derive(Clone)]
pub struct Map {
    /// The map's anchored object (queries hit it; `destroy` removes it).
    pub object: Object,
    /// Meshes read from the file.
    pub meshes: usize,
    /// The daemon's validation report.
    pub report: MapReport,
}

impl Map {
    /// The map's handle: what query hits (`Hit::object`), contact events and query filters
    /// name it by.
    pub fn handle(&self) -> shm_layout::Handle {
        self.object.handle()
    }

    /// The daemon's validation report (degenerate triangles dropped, duplicate vertices
    /// merged, non-manifold, welded and open edges).
    pub fn report(&self) -> &MapReport {
        &self.report
    }

    /// Whether the map still exists at the newest tick (false once destroyed, or once its
    /// plane is).
    pub fn is_alive(&self) -> Result<bool, Error> {
        self.object.is_alive()
    }

    /// Removes the map from its plane (sent with the next flush; reads see it gone at once).
    /// Destroying it again does nothing.
    pub fn destroy(&self) {
        if self.object.is_alive().unwrap_or(false) {
            self.object.destroy();
        }
    }

    /// The map's object while it exists; else a `StaleHandle` error naming the map.
    fn live(&self) -> Result<&Object, Error> {
        if self.object.is_alive()? {
            return Ok(&self.object);
        }
        Err(Error::Command(shm_layout::CommandError::new(
            shm_layout::ErrorKind::StaleHandle,
            format!(
                "map {} of plane {} was destroyed",
                self.handle(),
                self.object.plane().id()
            ),
        )))
    }

    /// Where the map's origin is (the newest tick, with this process's writes on top).
    pub fn pose(&self) -> Result<Pose, Error> {
        self.live()?.pose()
    }

    /// Moves the static map: bodies resting on it are woken and follow the new surface,
    /// queries see it after the next step. Maps stay anchored.
    pub fn set_pose(&self, pose: Pose) -> Result<(), Error> {
        self.live()?.set_pose(pose)
    }

    /// The map's surface friction, in [0, 1] (combined with a body's as `sqrt(a·b)`).
    pub fn set_friction(&self, mu: f32) -> Result<(), Error> {
        self.live()?.set_friction(mu)
    }

    /// The map's bounciness, clamped to [0, 1] (combined with a body's as the higher of
    /// the two).
    pub fn set_bounciness(&self, e: f32) -> Result<(), Error> {
        self.live()?.set_bounciness(e)
    }

    /// Whether bodies collide with the map (queries with `respect_can_collide` skip it
    /// when false).
    pub fn set_can_collide(&self, on: bool) -> Result<(), Error> {
        self.live()?.set_can_collide(on)
    }

    /// Puts the map in a registered collision group.
    pub fn set_collision_group(&self, name: &str) -> Result<(), Error> {
        self.live()?.set_collision_group(name)
    }

    /// The map's collision group, by name.
    pub fn collision_group(&self) -> Result<String, Error> {
        self.live()?.collision_group()
    }

    /// Friction, Bounciness, CanCollide and the collision group as the daemon holds them
    /// (the property mirror: one round trip the first time).
    pub fn properties(&self) -> Result<shm_layout::ObjectInfo, Error> {
        self.live()?.properties()
    }
}

fn file_error(path: &str, problem: impl std::fmt::Display) -> Error {
    Error::Invalid {
        field: "path".into(),
        message: format!("{path}: {problem}"),
    }
}

type Mat4 = [[f32; 4]; 4];

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (c, col) in m.iter_mut().enumerate() {
        for (r, v) in col.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    m
}

fn apply(m: &Mat4, p: [f32; 3]) -> [f32; 3] {
    let mut out = [0.0; 3];
    for (r, o) in out.iter_mut().enumerate() {
        *o = m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r];
    }
    out
}

/// Reads every mesh node of a .glb / .gltf file's default scene (or of its first scene, or
/// every root node when it has none), node transforms applied. Errors name the file and
/// the problem.
pub fn read_meshes(path: &Path) -> Result<Vec<MapMesh>, Error> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| file_error(&name, e))?;
    parse_meshes(&bytes, &name)
}

/// [`read_meshes`] on the bytes of a file; `name` names it in errors.
pub fn parse_meshes(bytes: &[u8], name: &str) -> Result<Vec<MapMesh>, Error> {
    let gltf = gltf::Gltf::from_slice(bytes)
        .map_err(|e| file_error(name, format!("not a valid glTF 2.0 file ({e})")))?;
    let blob = gltf.blob.as_deref();
    let doc = &gltf.document;
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => doc.nodes().collect(),
    };
    let identity: Mat4 = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let mut out = Vec::new();
    let mut stack: Vec<(gltf::Node, Mat4, usize)> =
        roots.into_iter().map(|n| (n, identity, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 64 {
            return Err(file_error(name, "node hierarchy deeper than 64 (a cycle?)"));
        }
        let world = mul(&parent, &node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            for (pi, prim) in mesh.primitives().enumerate() {
                let what = format!("mesh {} primitive {pi}", mesh.index());
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    return Err(file_error(
                        name,
                        format!("{what} is {:?}, only triangles are supported", prim.mode()),
                    ));
                }
                let reader = prim.reader(|b| match b.source() {
                    gltf::buffer::Source::Bin => blob,
                    gltf::buffer::Source::Uri(_) => None,
                });
                let positions: Vec<Vec3> = reader
                    .read_positions()
                    .ok_or_else(|| {
                        file_error(
                            name,
                            format!("{what} has no readable POSITION data (external buffers are not read)"),
                        )
                    })?
                    .map(|p| apply(&world, p))
                    .collect();
                if let Some(p) = positions.iter().find(|p| p.iter().any(|c| !c.is_finite())) {
                    return Err(file_error(
                        name,
                        format!("{what} has a non-finite vertex {p:?}"),
                    ));
                }
                let n = positions.len() as u32;
                let flat: Vec<u32> = match reader.read_indices() {
                    Some(i) => i.into_u32().collect(),
                    None => (0..n).collect(),
                };
                if !flat.len().is_multiple_of(3) {
                    return Err(file_error(
                        name,
                        format!("{what} has {} indices, not a multiple of 3", flat.len()),
                    ));
                }
                if let Some(i) = flat.iter().find(|&&i| i >= n) {
                    return Err(file_error(
                        name,
                        format!("{what}: index {i} is past its {n} vertices"),
                    ));
                }
                let mut triangles: Vec<[u32; 3]> =
                    flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
                // A mirroring transform flips the winding: keep triangles facing out.
                if det3(&world) < 0.0 {
                    for t in &mut triangles {
                        t.swap(1, 2);
                    }
                }
                out.push(MapMesh {
                    vertices: positions,
                    triangles,
                });
            }
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
        }
    }
    if out.iter().all(|m| m.triangles.is_empty()) {
        return Err(file_error(name, "the file has no triangle meshes"));
    }
    Ok(out)
}

fn det3(m: &Mat4) -> f32 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

/// Writes meshes as a .glb (one node per mesh, positions and u32 indices in the BIN chunk),
/// with the gltf crate's JSON types: what tests, examples and the bench load.
pub fn write_glb(meshes: &[MapMesh]) -> Vec<u8> {
    use json::validation::Checked::Valid;
    use json::validation::USize64;
    let mut root = json::Root::default();
    let mut bin: Vec<u8> = Vec::new();
    let buffer = root.push(json::Buffer {
        byte_length: USize64(0),
        extensions: None,
        extras: Default::default(),
        uri: None,
    });
    let mut nodes = Vec::new();
    for m in meshes {
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for v in &m.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let mut view = |bytes: &[u8], target| {
            let offset = bin.len();
            bin.extend_from_slice(bytes);
            while !bin.len().is_multiple_of(4) {
                bin.push(0);
            }
            root.push(json::buffer::View {
                buffer,
                byte_length: USize64(bytes.len() as u64),
                byte_offset: Some(USize64(offset as u64)),
                byte_stride: None,
                extensions: None,
                extras: Default::default(),
                target: Some(Valid(target)),
            })
        };
        let pos: Vec<u8> = m
            .vertices
            .iter()
            .flatten()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        let idx: Vec<u8> = m
            .triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let pos_view = view(&pos, json::buffer::Target::ArrayBuffer);
        let idx_view = view(&idx, json::buffer::Target::ElementArrayBuffer);
        let positions = root.push(json::Accessor {
            buffer_view: Some(pos_view),
            byte_offset: None,
            count: USize64(m.vertices.len() as u64),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(json::accessor::Type::Vec3),
            min: Some(serde_json::json!(lo)),
            max: Some(serde_json::json!(hi)),
            normalized: false,
            sparse: None,
        });
        let indices = root.push(json::Accessor {
            buffer_view: Some(idx_view),
            byte_offset: None,
            count: USize64(m.triangles.len() as u64 * 3),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(json::accessor::Type::Scalar),
            min: None,
            max: None,
            normalized: false,
            sparse: None,
        });
        let mesh = root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            primitives: vec![json::mesh::Primitive {
                attributes: [(Valid(json::mesh::Semantic::Positions), positions)].into(),
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: None,
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        });
        nodes.push(root.push(json::Node {
            mesh: Some(mesh),
            ..Default::default()
        }));
    }
    root.buffers[0].byte_length = USize64(bin.len() as u64);
    let scene = root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        nodes,
    });
    root.scene = Some(scene);
    let json_bytes = json::serialize::to_vec(&root).expect("glTF JSON serialises");
    let mut json_padded = json_bytes;
    while !json_padded.len().is_multiple_of(4) {
        json_padded.push(b' ');
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: (12 + 8 + json_padded.len() + 8 + bin.len()) as u32,
        },
        json: json_padded.into(),
        bin: Some(bin.into()),
    };
    glb.to_vec().expect("a well-formed GLB")
}

/// Splits meshes into upload pieces of at most [`MAX_PIECE`] vertices + triangles, each
/// with piece-local indices.
pub fn pieces(meshes: &[MapMesh]) -> Vec<MapMesh> {
    let mut out = Vec::new();
    let mut cur = MapMesh::default();
    let mut local: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for m in meshes {
        for t in &m.triangles {
            if cur.vertices.len() + cur.triangles.len() + 4 > MAX_PIECE {
                out.push(std::mem::take(&mut cur));
                local.clear();
            }
            let t = t.map(|i| {
                *local.entry(i).or_insert_with(|| {
                    cur.vertices.push(m.vertices[i as usize]);
                    cur.vertices.len() as u32 - 1
                })
            });
            cur.triangles.push(t);
        }
        if !cur.triangles.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
        local.clear();
    }
    out
}

/// Most bytes of map pieces sent in one request (the daemon refuses requests over 16 MiB
/// by default).
pub const MAP_REQUEST_BYTES: usize = 8 << 20;

impl Plane {
    /// Loads a .glb / .gltf as a static triangle-mesh map.
    pub fn load_map(&self, path: &Path, options: &MapOptions) -> Result<Map, Error> {
        let meshes = read_meshes(path)?;
        self.load_map_meshes(&meshes, options)
    }

    /// Uploads `meshes` (map space) as one static triangle-mesh map: the pieces go in
    /// requests of at most [`MAP_REQUEST_BYTES`], then the build, which checks the upload is
    /// complete, so the daemon builds all of it or nothing.
    pub fn load_map_meshes(&self, meshes: &[MapMesh], options: &MapOptions) -> Result<Map, Error> {
        let client = self.client();
        client.flush()?;
        // A leftover of an interrupted upload must not join this map.
        client.queue(
            Command::plane(self.id(), PlaneOp::Map(MapOp::Discard)),
            None,
        );
        let (mut nv, mut nt) = (0u64, 0u64);
        // Requests stay under the daemon's 16 MiB limit: pieces are flushed in requests of
        // at most MAP_REQUEST_BYTES (worst-case encoded size: 12 bytes a vertex, 15 a
        // triangle).
        let mut pending = 0usize;
        for piece in pieces(meshes) {
            let bytes = piece.vertices.len() * 12 + piece.triangles.len() * 15 + 64;
            if pending > 0 && pending + bytes > MAP_REQUEST_BYTES {
                if let Err(e) = client.flush() {
                    let _ = client.call(Command::plane(self.id(), PlaneOp::Map(MapOp::Discard)));
                    return Err(e);
                }
                pending = 0;
            }
            pending += bytes;
            nv += piece.vertices.len() as u64;
            nt += piece.triangles.len() as u64;
            let op = MapOp::Upload {
                vertices: piece.vertices,
                triangles: piece.triangles,
            }
            .checked()
            .map_err(Error::invalid_value)?;
            client.queue(Command::plane(self.id(), PlaneOp::Map(op)), None);
        }
        // Pieces refused (a quota, say) are reported here, before anything is built.
        if let Err(e) = client.flush() {
            let _ = client.call(Command::plane(self.id(), PlaneOp::Map(MapOp::Discard)));
            return Err(e);
        }
        let build = MapOp::Build {
            pose: options.pose,
            scale: options.scale,
            vertices: nv,
            triangles: nt,
        }
        .checked()
        .map_err(Error::invalid_value)?;
        let reply = match client.call(Command::plane(self.id(), PlaneOp::Map(build))) {
            Ok(r) => r,
            Err(e) => {
                // Leave nothing pending behind a failed upload.
                let _ = client.call(Command::plane(self.id(), PlaneOp::Map(MapOp::Discard)));
                return Err(e);
            }
        };
        // The map's body joins the plane's objects (and its tick is not in the reply).
        self.shared.members.borrow_mut().unknown_change();
        match reply {
            Reply::Map(info) => {
                // Until a sample shows it, the map reads back as built (as an added object
                // does): ask the daemon's tick once, so the overlay ends with the first
                // sample that holds the map.
                let tick = self.info()?.tick;
                self.shared.members.borrow_mut().asked(tick);
                self.overlay_write(info.handle, |e| {
                    e.pose = Some(options.pose);
                    e.velocity = Some([0.0; 3]);
                    e.angular_velocity = Some([0.0; 3]);
                    e.anchored = Some(true);
                });
                self.overlay_confirm(info.handle, tick);
                Ok(Map {
                    object: Object::from_handle(self, info.handle),
                    meshes: meshes.len(),
                    report: info.report,
                })
            }
            other => Err(Error::Protocol(format!("expected a map, got {other:?}"))),
        }
    }

    /// Loads a .glb as one dynamic object at `pose`: the convex hull of all its vertices,
    /// scaled by `scale`. With `decompose`, the file's meshes (each its own convex part) are
    /// objects welded by Fixed joints; the first is returned with the others.
    pub fn load_prop(
        &self,
        path: &Path,
        pose: Pose,
        scale: Vec3,
        decompose: bool,
        props: &[ObjectProp],
    ) -> Result<Vec<Object>, Error> {
        let name = path.display().to_string();
        let meshes = read_meshes(path)?;
        let scaled = |v: &Vec3| [v[0] * scale[0], v[1] * scale[1], v[2] * scale[2]];
        let parts: Vec<Vec<Vec3>> = if decompose {
            meshes
                .iter()
                .map(|m| m.vertices.iter().map(scaled).collect())
                .collect()
        } else {
            vec![meshes
                .iter()
                .flat_map(|m| m.vertices.iter().map(scaled))
                .collect()]
        };
        let mut objects: Vec<Object> = Vec::new();
        let mut c0 = [0.0; 3];
        for (i, vertices) in parts.into_iter().enumerate() {
            // Each part is centred on its own box so the object's origin sits inside it.
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for v in &vertices {
                for k in 0..3 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            let c = [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2.0);
            let local: Vec<Vec3> = vertices
                .iter()
                .map(|v| [v[0] - c[0], v[1] - c[1], v[2] - c[2]])
                .collect();
            let at = rotate(pose.rotation, c);
            let part_pose = Pose {
                position: [0, 1, 2].map(|k| pose.position[k] + at[k]),
                rotation: pose.rotation,
            };
            let shape = Shape::Mesh {
                vertices: local,
                triangles: Vec::new(),
            };
            let obj = self.add(shape, part_pose, props).map_err(|e| match e {
                Error::Invalid { field, message } => {
                    file_error(&name, format!("mesh {i}: invalid {field}: {message}"))
                }
                Error::Command(c) => file_error(&name, format!("mesh {i}: {}", c.message)),
                e => e,
            })?;
            if let Some(first) = objects.first() {
                // Same rotation for every part: A's local offset is the centres' difference.
                self.joint(
                    JointKind::Fixed,
                    first,
                    Some(&obj),
                    &[
                        shm_layout::JointProp::AnchorA([0, 1, 2].map(|k| c[k] - c0[k])),
                        shm_layout::JointProp::AnchorB([0.0; 3]),
                    ],
                )?;
            } else {
                c0 = c;
            }
            objects.push(obj);
        }
        Ok(objects)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_glb_reads_back_with_node_transforms() {
        let m = MapMesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 2, 1]],
        };
        let bytes = write_glb(std::slice::from_ref(&m));
        let back = parse_meshes(&bytes, "t.glb").unwrap();
        assert_eq!(back, vec![m]);
        let e = parse_meshes(b"garbage", "bad.glb").unwrap_err().to_string();
        assert!(
            e.contains("bad.glb") && e.contains("not a valid glTF"),
            "{e}"
        );
    }

    #[test]
    fn pieces_stay_within_the_limit_and_keep_every_triangle() {
        let n = 200u32;
        let mut m = MapMesh::default();
        for i in 0..=n {
            for j in 0..=n {
                m.vertices.push([i as f32, 0.0, j as f32]);
            }
        }
        for i in 0..n {
            for j in 0..n {
                let a = i * (n + 1) + j;
                m.triangles.push([a, a + 1, a + n + 1]);
                m.triangles.push([a + 1, a + n + 2, a + n + 1]);
            }
        }
        let ps = pieces(std::slice::from_ref(&m));
        assert!(ps
            .iter()
            .all(|p| p.vertices.len() + p.triangles.len() <= MAX_PIECE));
        assert_eq!(
            ps.iter().map(|p| p.triangles.len()).sum::<usize>(),
            m.triangles.len()
        );
    }
}
