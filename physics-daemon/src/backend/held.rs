//! Held objects (`ObjectProp::Held`, `GuiObjectProp::Held`): a step leaves them exactly
//! where it found them (pose and velocities restored after the step) until they are
//! released, or for at most `MAX_HELD_TICKS` ticks. The SDK adds objects held on planes
//! that tick by themselves and releases them with its next flush, so the writes a script
//! makes right after an add apply before the object's first step, whenever the plane's
//! ticks fall.
//!
//! Both rapier backends use the same code, generic over the engine's world
//! ([`RapierWorld`]): the plane keeps a `held: Vec<HeldIn<PhysicsWorld>>`, calls [`hold`] for
//! the property and [`before_step`] / [`after_step`] around rapier's step.

use shm_layout::settings::object::MAX_HELD_TICKS;

use super::rapier_world::RapierWorld;

/// One held body and its state before the current step (`M`: pose and velocities).
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct HeldBody<H, M> {
    handle: H,
    ticks: u32,
    saved: Option<M>,
}

/// A held body of the engine world `W`.
pub type HeldIn<W> = HeldBody<<W as RapierWorld>::BodyHandle, <W as RapierWorld>::Motion>;

/// Holds (`on`) or releases the body `h`.
pub fn hold<H: PartialEq, M>(held: &mut Vec<HeldBody<H, M>>, h: H, on: bool) {
    held.retain(|b| b.handle != h);
    if on {
        held.push(HeldBody {
            handle: h,
            ticks: 0,
            saved: None,
        });
    }
}

/// Before a step: forgets bodies gone or held long enough, remembers the others' state.
pub fn before_step<W: RapierWorld>(held: &mut Vec<HeldIn<W>>, world: &W) {
    if held.is_empty() {
        return;
    }
    held.retain(|b| b.ticks < MAX_HELD_TICKS && world.motion(b.handle).is_some());
    for b in held {
        b.saved = world.motion(b.handle);
        b.ticks += 1;
    }
}

/// After a step: puts every held body back where the step found it.
pub fn after_step<W: RapierWorld>(held: &[HeldIn<W>], world: &mut W) {
    for b in held {
        if let Some(m) = b.saved {
            world.set_motion(b.handle, m);
        }
    }
}
