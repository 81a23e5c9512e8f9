//! Every plane option and object property, defined once: its wire variant, its default,
//! its range (checked or clamped) and whether it may change after creation. The SDK runs
//! these checks to fail early, the daemon runs them again because it trusts no client, and
//! both read the defaults from here.
//!
//! Adding an object property or a plane option: one row in the family's table ([`object`],
//! [`plane`]; see [`table`]) plus its mapping onto the engine in the daemon's backend. The
//! controller and GUI families still list theirs by hand.

pub mod controller;
pub mod gui_object;
pub mod gui_plane;
pub mod object;
pub mod plane;
pub mod row;
pub mod table;

pub use controller::{ControllerProp, ControllerSettings};
pub use gui_object::{GuiObjectProp, GuiObjectSettings, GuiShape};
pub use gui_plane::{GuiPlaneProp, GuiPlaneSettings, Vec2};
pub use object::{ObjectProp, ObjectSettings, Pin, Restraint, RotateTo};
pub use plane::{PlaneOptions, PlaneProp, PlaneSettings};
