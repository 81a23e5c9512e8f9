//! Lua values and the host's value types: numbers, Luau's native `Vector`, `CFrame`, `Dim`
//! and the rotation maths behind CFrame, plus the `Primitives` module that makes them.
//!
//! This layer knows no API type (plane, object, part): the API and the property rows build
//! on it, never the other way round. An API type that wants a richer description in error
//! messages than its type name opts in through its metatable (see [`DESCRIBE`]).

mod cframe;
mod cframe_methods;
pub mod cframe_ud;
mod convert;
mod describe;
mod dim;
mod dim_methods;
pub mod rotation;
mod vector;

pub use cframe::CFrame;
pub use cframe_ud::CFrameCache;
pub use convert::{lua_number, new_vector, number, sdk_error, vector};
pub use describe::{describe, expected, finite_number, finite_vector, DESCRIBE};
pub use dim::{new_dim, Dim};
pub use dim_methods::dim_arg;

use mlua::{Lua, Table};

/// Builds the `Primitives` module (`Vector`, `CFrame`, `Dim`) and gives every vector its
/// methods.
pub fn module(lua: &Lua) -> mlua::Result<Table> {
    cframe_ud::install(lua, &cframe_methods::metatable(lua)?)?;
    let cframe_mod = lua.create_table()?;
    cframe_mod.set("new", lua.create_function(cframe_methods::new)?)?;
    cframe_mod.set("Angles", lua.create_function(cframe_methods::angles)?)?;
    cframe_mod.set("identity", CFrame::IDENTITY)?;

    let dim_mod = lua.create_table()?;
    dim_mod.set("new", lua.create_function(dim_methods::new)?)?;

    let primitives = lua.create_table()?;
    primitives.set("Vector", vector::module(lua)?)?;
    primitives.set("CFrame", cframe_mod)?;
    primitives.set("Dim", dim_mod)?;
    Ok(primitives)
}
