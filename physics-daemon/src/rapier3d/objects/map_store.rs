//! Triangle maps stored once, by content hash: the daemon keeps one copy of each map's
//! triangle mesh (its vertices, triangles and BVH), however many planes build it. A build
//! whose cleaned mesh the daemon already holds (another plane's map, or a map a restore
//! brought) takes that copy; a snapshot writes a map's mesh once (with its collider) and
//! the map object refers to it by its hash. The store holds weak references: a map goes
//! when the last plane that uses it does.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, Weak};

use rapier3d::parry::shape::{Shape, TriMesh};
use rapier3d::prelude::*;

/// Copies of meshes by content hash (weak: the planes own them).
type Copies = HashMap<u64, Vec<Weak<dyn Shape>>>;

/// The daemon's maps by content hash.
static STORE: Mutex<Option<Copies>> = Mutex::new(None);

/// The content hash of a triangle mesh: its vertices' bits, its triangles and its flags.
pub(crate) fn content_hash(mesh: &TriMesh) -> u64 {
    let mut bytes = Vec::with_capacity(mesh.vertices().len() * 12 + mesh.indices().len() * 12 + 4);
    for v in mesh.vertices() {
        for c in [v.x, v.y, v.z] {
            bytes.extend_from_slice(&c.to_bits().to_le_bytes());
        }
    }
    for t in mesh.indices() {
        for i in t {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    bytes.extend_from_slice(&mesh.flags().bits().to_le_bytes());
    shm_layout::snapshot::checksum(&bytes)
}

fn same(a: &TriMesh, b: &TriMesh) -> bool {
    a.flags() == b.flags()
        && a.indices() == b.indices()
        && a.vertices().len() == b.vertices().len()
        && a.vertices()
            .iter()
            .zip(b.vertices())
            .all(|(p, q)| [p.x, p.y, p.z].map(f32::to_bits) == [q.x, q.y, q.z].map(f32::to_bits))
}

/// The stored copy equal to `mesh` (hash `hash`), if the daemon holds one.
fn find(store: &mut Copies, hash: u64, mesh: &TriMesh) -> Option<SharedShape> {
    let copies = store.get_mut(&hash)?;
    copies.retain(|w| w.strong_count() > 0);
    copies
        .iter()
        .filter_map(Weak::upgrade)
        .find(|s| s.as_trimesh().is_some_and(|m| same(m, mesh)))
        .map(SharedShape)
}

/// `shape` (a freshly built triangle mesh), or the daemon's copy of the same content; its
/// content hash, and whether the daemon held it already.
pub(crate) fn share(shape: SharedShape) -> (SharedShape, u64, bool) {
    let Some(mesh) = shape.as_trimesh() else {
        return (shape, 0, false);
    };
    let hash = content_hash(mesh);
    let mut guard = STORE.lock().unwrap_or_else(|p| p.into_inner());
    let store = guard.get_or_insert_with(HashMap::new);
    if let Some(held) = find(store, hash, mesh) {
        return (held, hash, true);
    }
    store.retain(|_, copies| copies.iter().any(|w| w.strong_count() > 0));
    store
        .entry(hash)
        .or_default()
        .push(Arc::downgrade(&shape.0));
    (shape, hash, false)
}

/// Notes a copy a restore decoded (it carries its own: swapping a collider's shape would
/// reset its contact workspaces and break bit-for-bit continuation), so later builds of
/// the same mesh share it.
pub(crate) fn register(shape: &SharedShape) {
    let Some(mesh) = shape.as_trimesh() else {
        return;
    };
    let hash = content_hash(mesh);
    let mut guard = STORE.lock().unwrap_or_else(|p| p.into_inner());
    let store = guard.get_or_insert_with(HashMap::new);
    store.retain(|_, copies| {
        copies.retain(|w| w.strong_count() > 0);
        !copies.is_empty()
    });
    let copies = store.entry(hash).or_default();
    if !copies
        .iter()
        .any(|w| std::ptr::addr_eq(w.as_ptr(), Arc::as_ptr(&shape.0)))
    {
        copies.push(Arc::downgrade(&shape.0));
    }
}

/// How many distinct maps the daemon holds now (tests).
#[cfg(test)]
pub(crate) fn held() -> usize {
    let mut guard = STORE.lock().unwrap_or_else(|p| p.into_inner());
    let store = guard.get_or_insert_with(HashMap::new);
    store
        .values()
        .map(|c| c.iter().filter(|w| w.strong_count() > 0).count())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Backend;
    use crate::rapier3d::Plane;
    use shm_layout::{MapInfo, MapOp, PlaneOp, Pose, Reply, Shape};

    /// A 60 × 60 height grid of two triangles a cell, offset by `lift` (another content).
    fn terrain(lift: f32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let n = 60u32;
        let mut v = Vec::new();
        let mut t = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, z) = (i as f32 - 30.0, j as f32 - 30.0);
                v.push([x, lift + 0.3 * (x * 0.4).sin() * (z * 0.3).cos(), z]);
            }
        }
        for i in 0..n {
            for j in 0..n {
                let a = i * (n + 1) + j;
                t.push([a, a + 1, a + n + 2]);
                t.push([a, a + n + 2, a + n + 1]);
            }
        }
        (v, t)
    }

    fn build(plane: &mut Plane, lift: f32) -> MapInfo {
        let (vertices, triangles) = terrain(lift);
        let (nv, nt) = (vertices.len() as u64, triangles.len() as u64);
        plane
            .apply(PlaneOp::Map(MapOp::Upload {
                vertices,
                triangles,
            }))
            .unwrap();
        match plane
            .apply(PlaneOp::Map(MapOp::Build {
                pose: Pose::IDENTITY,
                scale: [1.0; 3],
                vertices: nv,
                triangles: nt,
            }))
            .unwrap()
        {
            Reply::Map(info) => *info,
            other => panic!("{other:?}"),
        }
    }

    /// Five balls dropped from just above the terrain at `lift` (they land within 20 ticks).
    fn with_balls(plane: &mut Plane, lift: f32) {
        for i in 0..5 {
            plane
                .apply(PlaneOp::AddObject {
                    shape: Shape::Sphere { radius: 0.5 },
                    pose: Pose::at([i as f32 * 2.0 - 4.0, lift + 1.5, 0.0]),
                    props: vec![],
                })
                .unwrap();
        }
    }

    /// One copy of a mesh across planes (and across a restore), and once in a snapshot.
    /// (The store is daemon-wide: this test's meshes are its own, lifted 1000 units.)
    #[test]
    fn a_map_is_held_once_by_the_daemon_and_once_in_a_snapshot() {
        let mut a = Plane::new(1, &[]).unwrap();
        let first = build(&mut a, 1000.0);
        assert!(!first.report.shared);
        assert_ne!(first.report.content_hash, 0);
        let mut b = Plane::new(2, &[]).unwrap();
        let second = build(&mut b, 1000.0);
        assert!(
            second.report.shared,
            "the same mesh in another plane is shared"
        );
        assert_eq!(second.report.content_hash, first.report.content_hash);
        let other = build(&mut b, 1001.0);
        assert!(!other.report.shared);
        assert_ne!(other.report.content_hash, first.report.content_hash);

        // A snapshot holds the mesh once: a map adds about one serialised copy of it.
        let mut bare = Plane::new(3, &[]).unwrap();
        with_balls(&mut bare, 1002.0);
        let mut mapped = Plane::new(4, &[]).unwrap();
        with_balls(&mut mapped, 1002.0);
        build(&mut mapped, 1002.0);
        for p in [&mut bare, &mut mapped] {
            p.step(1.0 / 60.0).unwrap();
        }
        let shape = {
            let (v, t) = terrain(1002.0);
            let v = v.into_iter().map(Vector::from).collect();
            SharedShape::trimesh_with_flags(v, t, TriMeshFlags::FIX_INTERNAL_EDGES).unwrap()
        };
        let one_copy = postcard::to_allocvec(&shape).unwrap().len();
        let added = mapped.snapshot().unwrap().len() - bare.snapshot().unwrap().len();
        assert!(
            added < one_copy + one_copy / 5,
            "a map of {one_copy} serialised bytes adds {added} to a snapshot"
        );

        // Restored, it continues bit for bit; the daemon keeps its mesh for later builds
        // once the plane it came from is gone.
        let snap = mapped.snapshot().unwrap();
        let mut restored = Plane::new(5, &[]).unwrap();
        restored.restore(&snap, &[]).unwrap();
        for _ in 0..30 {
            restored.step(1.0 / 60.0).unwrap();
            mapped.step(1.0 / 60.0).unwrap();
        }
        assert_eq!(restored.header().state_hash, mapped.header().state_hash);
        // The balls rest on the map (contacts with it were part of the continuation).
        let ball = restored.objects.iter().nth(1).unwrap().1.handle;
        let y = restored.world.bodies[ball].translation().y;
        assert!(
            (y - 1002.5).abs() < 0.4,
            "a ball rests on the terrain: y = {y}"
        );
        drop(mapped);
        let built = build(&mut b, 1002.0);
        assert!(
            built.report.shared,
            "a restored map's mesh is shared with a build"
        );
        assert!(held() >= 2);
    }
}
