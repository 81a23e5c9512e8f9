//! Triangle-mesh maps through a real daemon: a .glb written by the test (gltf JSON types),
//! loaded by the SDK, built by the daemon. No ghost collisions at tile seams, exact ray
//! heights, the validation report, bad files, quotas.

use client_sdk::map::{self, MapMesh};
use client_sdk::{Error, ErrorKind, MapOptions, ObjectProp, Pose, Shape};
use integration_tests::{no_damping, Scene, TestDaemon};

/// `n × n` tiles of `size`, each two triangles with its own four vertices (so every seam
/// is two separate meshes' edges until the daemon merges them), top face y = 0, wound
/// counter-clockwise seen from above.
fn tiles(n: usize, size: f32) -> MapMesh {
    let mut m = MapMesh::default();
    let h = n as f32 * size / 2.0;
    for i in 0..n {
        for j in 0..n {
            let b = m.vertices.len() as u32;
            let (x, z) = (i as f32 * size - h, j as f32 * size - h);
            m.vertices.extend([
                [x, 0.0, z],
                [x + size, 0.0, z],
                [x + size, 0.0, z + size],
                [x, 0.0, z + size],
            ]);
            m.triangles.push([b, b + 2, b + 1]);
            m.triangles.push([b, b + 3, b + 2]);
        }
    }
    m
}

fn write_tmp(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("physics-maps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn a_tiled_map_has_no_ghost_bumps_and_rays_hit_it_exactly() {
    let s = Scene::new("map", no_damping());
    let path = write_tmp("grid.glb", &map::write_glb(&[tiles(100, 1.0)]));
    let m = s
        .plane
        .load_map(
            &path,
            &MapOptions {
                pose: Pose::at([0.0, 3.0, 0.0]),
                ..MapOptions::default()
            },
        )
        .unwrap();
    let r = &m.report;
    println!("report: {r:?}");
    assert_eq!(r.triangles, 20_000);
    assert_eq!(r.vertices, 101 * 101);
    // Pieces repeat a few vertices at their seams: every one of them merged away.
    assert_eq!(r.duplicate_vertices_merged, r.vertices_in - 101 * 101);
    // 100×100 grid with diagonals: 2·100·101 axis edges + 10,000 diagonals; 400 border.
    assert_eq!(r.open_edges, 400);
    assert_eq!(r.welded_edges, 2 * 100 * 101 + 10_000 - 400);
    assert_eq!(r.non_manifold_edges + r.degenerate_triangles, 0);

    // A ray straight down meets the surface at y = 3 (f32: a few ulps of 3).
    let hit = s
        .plane
        .raycast([12.3, 20.0, -7.7], [0.0, -50.0, 0.0], None)
        .unwrap()
        .expect("the ray misses the map");
    assert_eq!(hit.object, m.object.handle());
    assert!((hit.position[1] - 3.0).abs() < 1e-5, "{hit:?}");
    assert!((hit.normal[1] - 1.0).abs() < 1e-5, "{hit:?}");

    // A box sliding across 80 seams: friction 0 so it keeps its speed; any ghost
    // collision at a seam would kick it upward.
    let cube = s
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([-45.0, 3.5, 0.3]),
            &[ObjectProp::Friction(0.0)],
        )
        .unwrap();
    s.run(1.0 / 60.0, 30); // settle
    cube.set_velocity([20.0, 0.0, 0.0]).unwrap();
    let mut worst_vy = 0.0f32;
    for _ in 0..240 {
        s.plane.step(1.0 / 60.0).unwrap();
        worst_vy = worst_vy.max(cube.velocity().unwrap()[1].abs());
    }
    let x = cube.position().unwrap()[0];
    println!("box: worst |vy| {worst_vy}, travelled to x = {x}");
    assert!(x > 30.0, "the box stopped at x = {x}");
    assert!(worst_vy < 0.05, "ghost collision: |vy| reached {worst_vy}");

    // A ball rolling across the seams does not hop: its centre stays at r above the map.
    let ball = s
        .plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([-45.0, 3.5, 5.3]),
            &[],
        )
        .unwrap();
    s.run(1.0 / 60.0, 30);
    ball.set_velocity([15.0, 0.0, 0.0]).unwrap();
    let mut worst_dy = 0.0f32;
    for _ in 0..240 {
        s.plane.step(1.0 / 60.0).unwrap();
        worst_dy = worst_dy.max((ball.position().unwrap()[1] - 3.5).abs());
    }
    println!("ball: worst |y - (3 + r)| {worst_dy}");
    // Resting contact (no skins) keeps the height within the solver's allowed error.
    assert!(worst_dy < 0.03, "the ball hopped by {worst_dy}");

    // The map is static: reshaping it is refused with the property named.
    m.object.set_size([1.0; 3]).unwrap();
    let e = s
        .client
        .flush()
        .expect_err("Size accepted on a map")
        .to_string();
    assert!(e.contains("Size") && e.contains("map"), "{e}");
}

#[test]
fn bad_files_name_the_file_and_quotas_bound_maps() {
    let daemon = TestDaemon::start_with(
        "mapquota",
        &["--max-mesh-vertices-per-client", "30000"],
        &[],
    );
    let client = daemon.client();
    let plane = client
        .create_plane(&client_sdk::PlaneOptions::manual())
        .unwrap();
    let bad = write_tmp("broken.glb", b"glTF\x02\0\0\0garbage");
    let e = plane
        .load_map(&bad, &MapOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("broken.glb"), "{e}");
    let missing = std::path::Path::new("/nonexistent/nothing.glb");
    let e = plane
        .load_map(missing, &MapOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("nothing.glb"), "{e}");
    // Quota units are vertices + triangles: 60 × 60 = 14,400 + 7,200 = 21,600 quota units: fits; a second one does not.
    let small = plane
        .load_map_meshes(&[tiles(60, 1.0)], &MapOptions::default())
        .unwrap();
    assert_eq!(small.report.triangles, 7_200);
    match plane.load_map_meshes(&[tiles(60, 1.0)], &MapOptions::default()) {
        Err(Error::Batch(errors)) => {
            assert!(
                errors.iter().any(|e| e.kind == ErrorKind::Quota),
                "{errors:?}"
            )
        }
        other => panic!(
            "second map accepted past the quota: {:?}",
            other.map(|m| m.report)
        ),
    }
    // Nothing was half-loaded: one object, and the quota is free again once it goes.
    assert_eq!(plane.info().unwrap().object_count, 1);
    small.object.destroy();
    let again = plane
        .load_map_meshes(&[tiles(60, 1.0)], &MapOptions::default())
        .unwrap();
    assert_eq!(again.report.triangles, 7_200);
    // All-degenerate maps are refused.
    let flat = MapMesh {
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    };
    let e = plane
        .load_map_meshes(&[flat], &MapOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("degenerate"), "{e}");
}

#[test]
fn a_prop_loads_as_one_convex_object() {
    let s = Scene::new("prop", no_damping());
    s.floor();
    // A unit cube's 8 corners as a mesh file.
    let mut cube = MapMesh::default();
    for i in 0..8u32 {
        cube.vertices
            .push([(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]);
    }
    cube.triangles = vec![
        [0, 1, 2],
        [1, 3, 2],
        [4, 6, 5],
        [5, 6, 7],
        [0, 4, 1],
        [1, 4, 5],
        [2, 3, 6],
        [3, 7, 6],
        [0, 2, 4],
        [2, 6, 4],
        [1, 5, 3],
        [3, 5, 7],
    ];
    let path = write_tmp("crate.glb", &map::write_glb(&[cube]));
    let objs = s
        .plane
        .load_prop(&path, Pose::at([0.0, 5.0, 0.0]), [2.0; 3], false, &[])
        .unwrap();
    assert_eq!(objs.len(), 1);
    s.run(1.0 / 60.0, 120);
    let y = objs[0].position().unwrap()[1];
    // A 2-unit cube rests with its centre 1 above the floor.
    assert!((y - 1.0).abs() < 0.05, "prop rests at {y}");
}

/// The .glb files the examples and Luau tests load are the ones `integration_tests::assets`
/// generates (byte for byte), so they are reproducible and never downloaded.
#[test]
fn shipped_example_glbs_are_the_generated_ones() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for (path, meshes) in integration_tests::assets::all() {
        let bytes = map::write_glb(&meshes);
        let file = root.join(path);
        if std::env::var("PHYSICS_WRITE_ASSETS").is_ok_and(|v| v == "1") {
            std::fs::write(&file, &bytes).unwrap();
        }
        let shipped = std::fs::read(&file)
            .unwrap_or_else(|e| panic!("{path}: {e} (PHYSICS_WRITE_ASSETS=1 writes it)"));
        assert!(
            shipped == bytes,
            "{path} differs from the generated file (PHYSICS_WRITE_ASSETS=1 rewrites it)"
        );
        // Small enough to ship, and what it says it is.
        assert!(bytes.len() < 16 * 1024, "{path}: {} bytes", bytes.len());
        let read = map::read_meshes(&file).unwrap();
        assert_eq!(read.len(), meshes.len(), "{path}: mesh count");
    }
}

#[test]
fn a_character_controller_walks_across_a_tiled_map() {
    let s = Scene::new("map-kcc", no_damping());
    s.plane
        .load_map_meshes(&[tiles(60, 1.0)], &MapOptions::default())
        .unwrap();
    // A capsule of radius 1 and height 5 standing on the map's top face (y = 0).
    let c = s
        .plane
        .new_controller(Pose::at([-20.0, 2.51, 0.0]), [2.0, 5.0, 2.0], false, &[])
        .unwrap();
    s.run(1.0 / 60.0, 10);
    assert!(c.on_ground().unwrap(), "stands on the map");
    // Facing +X (yaw −π/2: the LookVector (−sin y, 0, −cos y) is +X), walking forward: 2 s
    // at WalkSpeed 16 crosses 30 tile seams.
    c.set(client_sdk::ControllerProp::Rotation([
        0.0,
        -std::f32::consts::FRAC_PI_2,
        0.0,
    ]))
    .unwrap();
    c.set_move_vector(0.0, 1.0).unwrap();
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    let mut airborne = 0;
    for _ in 0..120 {
        s.plane.step(1.0 / 60.0).unwrap();
        let p = c.object().position().unwrap();
        lo = lo.min(p[1]);
        hi = hi.max(p[1]);
        airborne += usize::from(!c.on_ground().unwrap());
    }
    let p = c.object().position().unwrap();
    assert!(p[0] > 5.0, "walked across the seams: x {}", p[0]);
    assert_eq!(airborne, 0, "never left the ground at a seam");
    assert!(
        hi - lo < 0.02,
        "no bumps at the seams: height varied {}",
        hi - lo
    );
}

/// The SDK's `Map` is a handle: hits name it, filters take it, its collision group,
/// material, pose and existence change through it, and writes after `destroy` are refused
/// with the map named.
#[test]
fn a_map_handle_filters_groups_moves_and_destroys_its_map() {
    let s = Scene::new("map-handle", no_damping());
    let m = s
        .plane
        .load_map_meshes(&[tiles(20, 1.0)], &MapOptions::default())
        .unwrap();
    let down = [0.0, -20.0, 0.0];
    let hit = s.plane.raycast([1.2, 10.0, 1.7], down, None).unwrap();
    assert_eq!(hit.map(|h| h.object), Some(m.handle()));
    assert_eq!(m.report().triangles, 800);
    // Read back before any sample holds it: the pose it was built at.
    assert_eq!(m.pose().unwrap().position, [0.0; 3]);
    let excluded = client_sdk::QueryParams {
        filter: vec![m.handle()],
        ..Default::default()
    };
    assert_eq!(
        s.plane
            .raycast([1.2, 10.0, 1.7], down, Some(&excluded))
            .unwrap(),
        None,
        "the filtered map is not hit"
    );

    // A group that does not collide with the map's falls through; Default rests on it.
    s.client.register_collision_group("Terrain").unwrap();
    s.client.register_collision_group("Ghosts").unwrap();
    s.client
        .collision_group_set_collidable("Terrain", "Ghosts", false)
        .unwrap();
    m.set_collision_group("Terrain").unwrap();
    assert_eq!(m.collision_group().unwrap(), "Terrain");
    let ghosts = s.client.collision_group_id("Ghosts").unwrap();
    let ghost = s
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([3.0, 2.0, 3.0]),
            &[ObjectProp::CollisionGroup(ghosts)],
        )
        .unwrap();
    let solid = s
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([-3.0, 2.0, -3.0]),
            &[],
        )
        .unwrap();
    s.run(1.0 / 60.0, 60);
    // Free fall for 1 s in 240 substeps of 1/240 s (4 per step): y0 - g·h²·N(N+1)/2.
    let h = 1.0f32 / 240.0;
    let fell = 2.0 - 50.0 * h * h * 240.0 * 241.0 / 2.0;
    let gy = ghost.position().unwrap()[1];
    assert!(
        (gy - fell).abs() < 0.01,
        "ghost at {gy}, free fall says {fell}"
    );
    let sy = solid.position().unwrap()[1];
    assert!((sy - 0.5).abs() < 0.02, "the Default cube rests at {sy}");

    // Material writes read back from the daemon.
    m.set_friction(0.25).unwrap();
    m.set_bounciness(0.75).unwrap();
    m.set_can_collide(true).unwrap();
    let props = m.properties().unwrap();
    assert_eq!((props.friction, props.bounciness), (0.25, 0.75));
    let e = m.set_friction(f32::NAN).unwrap_err().to_string();
    assert!(e.contains("Friction"), "{e}");
    let e = m.set_collision_group("Nope").unwrap_err().to_string();
    assert!(e.contains("Nope"), "{e}");

    // The static map moves: rays meet it at its new height after a step.
    m.set_pose(Pose::at([0.0, 5.0, 0.0])).unwrap();
    assert_eq!(m.pose().unwrap().position, [0.0, 5.0, 0.0]);
    s.plane.step(1.0 / 60.0).unwrap();
    let hit = s
        .plane
        .raycast([1.2, 20.0, 1.7], [0.0, -30.0, 0.0], None)
        .unwrap()
        .expect("the moved map is hit");
    assert_eq!(hit.object, m.handle());
    assert!((hit.position[1] - 5.0).abs() < 1e-5, "{hit:?}");

    // Destroyed: gone from queries, a second destroy does nothing, writes name the map.
    m.destroy();
    m.destroy();
    assert!(!m.is_alive().unwrap());
    s.plane.step(1.0 / 60.0).unwrap();
    assert_eq!(
        s.plane
            .raycast([1.2, 20.0, 1.7], [0.0, -30.0, 0.0], None)
            .unwrap()
            .map(|h| h.object),
        None
    );
    let e = m.set_friction(0.5).unwrap_err().to_string();
    assert!(e.contains("map") && e.contains("destroyed"), "{e}");
    s.client.flush().unwrap();
}
