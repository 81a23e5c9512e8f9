//! The property names the runtime gives each Lua type (the rows of `props`), listed for the
//! test that keeps `types/physics.d.luau` in step with them (`tests/tests/lua/definitions.rs`).

use crate::props;

/// Every property table of the runtime: the Lua type's name and its property names, in
/// row order.
pub fn property_rows() -> Vec<(&'static str, Vec<&'static str>)> {
    fn names<T: props::Target>(p: &props::Props<T>) -> (&'static str, Vec<&'static str>) {
        let rows = p.rows.iter().chain(p.table_rows());
        (p.owner, rows.map(|r| r.name).collect())
    }
    vec![
        names(&crate::api::part::props::PART),
        names(&crate::api::object::props::OBJECT),
        names(&crate::api::plane::props::PLANE),
        names(&crate::api::controller::props::CONTROLLER),
        names(&crate::api::gui_plane::props::GUI_PLANE),
        names(&crate::api::gui_object::props::GUI_OBJECT),
        names(&crate::api::map::MAP),
    ]
}
