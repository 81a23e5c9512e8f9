//! A rapier plane's state as a value, its fields listed once: [`plane_state!`] makes the
//! borrowed `StateRef` (what a snapshot encodes), the owned `State` (what a restore decodes
//! and Rewind keeps) and the copies between them, for the plane's module it is used in.
//! The engine's world comes first (copied through
//! [`RapierWorld::copy`](super::rapier_world::RapierWorld::copy): its sets cloned, its
//! per-step workspaces fresh); the other fields are the plane's own and `Clone`. Both
//! encode as the plane's fields in the order given, one after the other.
//!
//! The plane fills a `StateRef` from its fields and takes a `State`'s apart (its own
//! `state_ref` and `take_state`, where the compiler checks that every field is named).

/// Expands `StateRef<'a>`, `State`, `StateRef::to_state`, `From<&State> for StateRef` and
/// [`Duplicate`](super::rollback::Duplicate) for `State`, from `world: WORLD_TYPE` and the
/// plane's own fields.
macro_rules! plane_state {
    (world: $world:ty, $($field:ident: $ty:ty,)*) => {
        /// The plane's state, borrowed (to encode).
        #[derive(serde::Serialize)]
        pub(super) struct StateRef<'a> {
            pub(super) world: &'a $world,
            $(pub(super) $field: &'a $ty,)*
        }

        /// The plane's state, owned (decoded from a snapshot, or a copy kept for Rewind).
        #[derive(serde::Deserialize)]
        pub(super) struct State {
            pub(super) world: $world,
            $(pub(super) $field: $ty,)*
        }

        impl StateRef<'_> {
            /// An owned copy: the engine's sets cloned (shapes shared), its per-step
            /// workspaces fresh, the plane's own fields cloned.
            pub(super) fn to_state(&self) -> State {
                State {
                    world: $crate::backend::rapier_world::RapierWorld::copy(self.world),
                    $($field: self.$field.clone(),)*
                }
            }
        }

        impl<'a> From<&'a State> for StateRef<'a> {
            fn from(state: &'a State) -> StateRef<'a> {
                StateRef { world: &state.world, $($field: &state.$field,)* }
            }
        }

        impl $crate::backend::rollback::Duplicate for State {
            fn duplicate(&self) -> State {
                StateRef::from(self).to_state()
            }
        }
    };
}

pub(crate) use plane_state;
