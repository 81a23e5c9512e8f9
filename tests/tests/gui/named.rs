//! GUI planes as named, persistent and rewindable planes, through real daemons:
//! `RollbackTicks`/`Rewind` go back bit for bit (the same hashes and poses as the first
//! time, a corrected input takes effect, too far back is refused by name), and a
//! `Name`d `Persistent` GUI plane is listed, survives a SIGKILL of its daemon and is opened
//! from the next one at its saved tick, its falling square where the closed form puts it.

use std::path::PathBuf;

use client_sdk::{
    Client, GuiObject, GuiPlane, GuiPlaneOptions, PlaneKind, PlaneName, PlaneOptions, PlaneProp,
};
use integration_tests::{unique_domain, TestDaemon};
use shm_layout::settings::GuiShape;

const DT: f32 = 1.0 / 60.0;
/// The GUI planes' default gravity (px/s², +Y down).
const G: f32 = 980.0;

fn undamped(extra: GuiPlaneOptions) -> GuiPlaneOptions {
    GuiPlaneOptions {
        linear_damping: Some(0.0),
        angular_damping: Some(0.0),
        tick_rate: Some(0.0),
        ..extra
    }
}

/// Twelve squares falling into a box (they collide: contacts are part of what comes back).
fn pile(client: &Client, rollback_ticks: u32) -> (GuiPlane, Vec<GuiObject>) {
    let plane = client
        .create_gui_plane(&undamped(GuiPlaneOptions {
            bounds: Some(([0.0, 0.0], [400.0, 300.0])),
            rollback_ticks: Some(rollback_ticks),
            ..Default::default()
        }))
        .unwrap();
    let objects = (0..12)
        .map(|i| {
            let at = [40.0 + 27.0 * (i % 6) as f32, 200.0 + 35.0 * (i / 6) as f32];
            plane.add(GuiShape::Square, [30.0, 30.0], at, &[]).unwrap()
        })
        .collect();
    (plane, objects)
}

#[test]
fn gui_planes_rewind_bit_for_bit() {
    let daemon = TestDaemon::start("gui-rewind");
    let client = daemon.client();
    let (plane, objects) = pile(&client, 4);
    let mut hashes = vec![plane.plane().state_hash().unwrap()];
    let mut poses = vec![objects[3].position().unwrap()];
    for t in 1..=10u64 {
        if t == 6 {
            objects[3].apply_impulse([0.0, -900.0]).unwrap();
        }
        assert_eq!(plane.step(DT).unwrap(), t);
        hashes.push(plane.plane().state_hash().unwrap());
        poses.push(objects[3].position().unwrap());
    }
    assert!(hashes.windows(2).all(|w| w[0] != w[1]), "the pile moves");
    // Back to tick 7: its hash and poses exactly, then the same ticks again.
    assert_eq!(plane.plane().rewind(3).unwrap(), 7);
    assert_eq!(plane.plane().state_hash().unwrap(), hashes[7]);
    assert_eq!(objects[3].position().unwrap(), poses[7]);
    for (t, expected) in hashes.iter().enumerate().skip(8) {
        plane.step(DT).unwrap();
        assert_eq!(plane.plane().state_hash().unwrap(), *expected, "tick {t}");
    }
    // A corrected input after a rewind takes effect from its tick on.
    assert_eq!(plane.plane().rewind(2).unwrap(), 8);
    objects[5].apply_impulse([500.0, 0.0]).unwrap();
    plane.step(DT).unwrap();
    assert_ne!(plane.plane().state_hash().unwrap(), hashes[9]);
    // Further back than kept is refused by name, and so is a plane that keeps nothing.
    let e = plane.plane().rewind(5).unwrap_err().to_string();
    assert!(e.contains("RollbackTicks = 4"), "{e}");
    let (none, _) = pile(&client, 0);
    none.step(DT).unwrap();
    let e = none.plane().rewind(1).unwrap_err().to_string();
    assert!(e.contains("needs RollbackTicks > 0"), "{e}");
    assert_eq!(plane.plane().info().unwrap().rollback_ticks, 4);
}

/// A state directory of its own, removed at the end.
struct StateDir(PathBuf);

impl Drop for StateDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn a_named_persistent_gui_plane_survives_a_sigkill_and_is_opened_again() {
    let state = StateDir(std::env::temp_dir().join(unique_domain("state-gui")));
    std::fs::create_dir_all(&state.0).unwrap();
    let dir = state.0.to_str().unwrap().to_string();
    let domain = unique_domain("gui-persist");
    let args = ["--state-dir", dir.as_str(), "--snapshot-every", "3600"];
    let name = PlaneName::new("hud-1").unwrap();
    let y0 = 50.0;
    let (handle, saved_hash, next_hash) = {
        let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
        let a = daemon.client();
        let plane = a
            .create_gui_plane(&undamped(GuiPlaneOptions {
                name: Some(name),
                persistent: Some(true),
                ..Default::default()
            }))
            .unwrap();
        assert_eq!(plane.plane().name().unwrap().as_deref(), Some("hud-1"));
        // Names are unique across kinds.
        let e = a
            .create_plane(&PlaneOptions::manual().with(PlaneProp::Name(name)))
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"hud-1\" is taken"), "{e}");
        let square = plane
            .add(GuiShape::Square, [20.0, 20.0], [100.0, y0], &[])
            .unwrap();
        for _ in 0..30 {
            plane.step(DT).unwrap();
        }
        assert_eq!(plane.plane().save().unwrap(), 30);
        let hash = plane.plane().state_hash().unwrap();
        plane.step(DT).unwrap();
        let next = plane.plane().state_hash().unwrap();
        daemon.kill9();
        (square.handle(), hash, next)
    };
    let daemon = TestDaemon::start_with_in(&domain, &args, &[]);
    let b = daemon.client();
    let list = b.list_planes().unwrap();
    assert_eq!(list.len(), 1, "{list:?}");
    assert_eq!(
        (
            list[0].name.as_str(),
            list[0].kind,
            list[0].tick,
            list[0].orphaned
        ),
        ("hud-1", PlaneKind::Gui2d, 30, true)
    );
    let opened = b.open_named("hud-1").unwrap();
    assert!(opened.owner);
    let plane = GuiPlane::from_plane(opened.plane);
    assert_eq!(plane.plane().state_hash().unwrap(), saved_hash);
    // Free fall from rest for 30 ticks, each SolverIterations (4) substeps of semi-implicit
    // Euler with h = dt/4: y = y0 + g·h²·m(m+1)/2 after m = 120 substeps, exactly in real
    // numbers; f32 rounding over 120 substeps stays far below 0.01 px.
    let square = GuiObject::from_handle(&plane, handle);
    let [x, y] = square.position().unwrap();
    let (m, h) = (120.0f32, DT / 4.0);
    let exact = y0 + G * h * h * m * (m + 1.0) / 2.0;
    assert_eq!(x, 100.0);
    assert!((y - exact).abs() < 0.01, "y = {y}, closed form {exact}");
    // And it goes on as the first run did.
    plane.step(DT).unwrap();
    assert_eq!(plane.plane().state_hash().unwrap(), next_hash);
}
