//! The property names the runtime gives each Lua type (the rows of `props`), listed for the
//! test that keeps `types/physics.d.luau` in step with them (`tests/tests/lua_definitions.rs`).

use crate::props;

/// Every property table of the runtime: the Lua type's name and its property names, in
/// row order.
pub fn property_rows() -> Vec<(&'static str, Vec<&'static str>)> {
    fn names<T: props::Target>(p: &props::Props<T>) -> (&'static str, Vec<&'static str>) {
        let rows = p.rows.iter().chain(T::table_rows());
        (p.owner, rows.map(|r| r.name).collect())
    }
    vec![
        names(&props::part::PART),
        names(&props::object::OBJECT),
        names(&props::plane::PLANE),
        names(&props::controller::CONTROLLER),
        (
            "GuiPhysicsPlane",
            props::gui::GUI_PLANE_ROWS.iter().map(|r| r.name).collect(),
        ),
        (
            "PhysicsGuiObject",
            props::gui::GUI_OBJECT_ROWS.iter().map(|r| r.name).collect(),
        ),
        names(&crate::api::map::MAP),
    ]
}
