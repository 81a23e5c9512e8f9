//! One `GUIController`'s state (it lives in its body): its settings, the input it was last
//! given, its path and what its signals compare against (see `controllers`).

use shm_layout::gui_op::GuiControllerSettings;
use shm_layout::settings::Vec2;

use crate::backend::counted::CountedVec;

/// One controller (lives in its body).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Controller {
    pub(super) settings: GuiControllerSettings,
    pub(super) uncontrolled: bool,
    pub(super) move_direction: Vec2,
    pub(super) jump: bool,
    /// Counted in the plane's state bytes (a client's quota).
    pub(super) waypoints: CountedVec<Vec2>,
    pub(super) next: usize,
    pub(super) on_ground: bool,
    pub(super) last_position: Vec2,
}

impl Controller {
    /// Moves the count of the waypoints to `counter` (a controller restored from a
    /// snapshot counts in its new plane).
    pub fn count_in(&mut self, counter: &crate::backend::counted::Counter) {
        self.waypoints.count_in(counter);
    }
}
