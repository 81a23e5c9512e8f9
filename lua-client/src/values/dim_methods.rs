//! The Lua side of a `Dim` value: its fields and operators, `Dim.new` and Dim arguments.

use mlua::{Lua, MetaMethod, UserData, UserDataFields, UserDataMethods, Value};

use super::convert::number;
use super::describe::{expected, finite_number};
use super::dim::Dim;

fn dim_value(what: &str, v: &Value) -> mlua::Result<Dim> {
    match v {
        Value::UserData(ud) => ud
            .borrow::<Dim>()
            .map(|d| *d)
            .map_err(|_| expected(what, "a Dim", v)),
        _ => Err(expected(what, "a Dim", v)),
    }
}

/// Dim ∘ Dim component-wise, or Dim ∘ number on both components.
fn arith(what: &str, a: &Value, b: &Value, op: fn(f64, f64) -> f64) -> mlua::Result<Dim> {
    let lhs = dim_value(what, a)?;
    match (number(b), b) {
        (Some(n), _) => Ok(Dim {
            x: op(lhs.x, n),
            y: op(lhs.y, n),
        }),
        (None, _) => {
            let rhs = dim_value(what, b)?;
            Ok(Dim {
                x: op(lhs.x, rhs.x),
                y: op(lhs.y, rhs.y),
            })
        }
    }
}

impl UserData for Dim {
    fn add_fields<F: UserDataFields<Self>>(fields: &mut F) {
        fields.add_field_method_get("X", |_, d| Ok(d.x));
        fields.add_field_method_get("Y", |_, d| Ok(d.y));
        fields.add_field_method_get("Magnitude", |_, d| Ok(d.x.hypot(d.y)));
    }

    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_function(MetaMethod::Add, |_, (a, b): (Value, Value)| {
            arith("Dim + Dim", &a, &b, |x, y| x + y)
        });
        methods.add_meta_function(MetaMethod::Sub, |_, (a, b): (Value, Value)| {
            arith("Dim - Dim", &a, &b, |x, y| x - y)
        });
        methods.add_meta_function(MetaMethod::Mul, |_, (a, b): (Value, Value)| {
            // number * Dim as well as Dim * number.
            if number(&a).is_some() {
                arith("number * Dim", &b, &a, |x, y| x * y)
            } else {
                arith("Dim * ...", &a, &b, |x, y| x * y)
            }
        });
        methods.add_meta_function(MetaMethod::Div, |_, (a, b): (Value, Value)| {
            arith("Dim / ...", &a, &b, |x, y| x / y)
        });
        methods.add_meta_method(MetaMethod::Unm, |_, d, ()| Ok(Dim { x: -d.x, y: -d.y }));
        methods.add_meta_method(MetaMethod::Eq, |_, d, o: Value| {
            Ok(dim_value("==", &o).is_ok_and(|o| o == *d))
        });
        methods.add_meta_method(MetaMethod::ToString, |_, d, ()| Ok(d.to_string()));
    }
}

/// `Dim.new(x, y)`; missing components are 0.
pub fn new(_: &Lua, (x, y): (Value, Value)) -> mlua::Result<Dim> {
    let comp = |name: &str, v: &Value| match v {
        Value::Nil => Ok(0.0),
        v => finite_number(&format!("Dim.new {name}"), v),
    };
    Ok(Dim {
        x: comp("x", &x)?,
        y: comp("y", &y)?,
    })
}

/// A Dim argument as pixels, or an error naming `what`, the expectation and the value.
pub fn dim_arg(what: &str, v: &Value) -> mlua::Result<[f32; 2]> {
    let bad = || expected(what, "a Dim with finite components", v);
    match v {
        Value::UserData(ud) => {
            let d = ud.borrow::<Dim>().map_err(|_| bad())?;
            if d.x.is_finite() && d.y.is_finite() {
                Ok([d.x as f32, d.y as f32])
            } else {
                Err(bad())
            }
        }
        _ => Err(bad()),
    }
}
