//! Static shapes built from planes: `Renderable.Plane(normal, offset)`, an infinite ground
//! (the half-space `normal · x ≤ offset`), and `Renderable.Brush(planes)`, the convex solid
//! bounded by a list of such half-spaces (a level editor's brush) as a MeshPart: the convex
//! hull of the planes' intersection points. Both are added anchored.
//!
//! A Plane is an anchored box [`PLANE_EXTENT`] wide and [`PLANE_DEPTH`] deep whose top face
//! is the plane: to every contact, query and controller it is the same surface as a true
//! half-space anywhere within ±[`PLANE_EXTENT`]/2 of its centre (the point `normal ·
//! offset`), and the daemon's box-exact queries keep rays, sweeps and controllers exact on
//! it at any size.

use mlua::{Lua, Table, Value};

use super::part::state::{PartShape, PartState};
use crate::values::rotation::{Quat, V3};
use crate::values::{expected, finite_number, finite_vector, CFrame};

/// Width of a Plane's box along its surface: the largest Size a part may have.
pub const PLANE_EXTENT: f32 = client_sdk::validate::MAX_SIZE;
/// Depth of a Plane's box below its surface: deep enough that nothing falls through it,
/// shallow enough that its top face keeps f32 precision (a contact's local depth is
/// measured from the box's centre, 50 units down).
pub const PLANE_DEPTH: f32 = 100.0;

fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: V3, k: f32) -> V3 {
    a.map(|c| c * k)
}

/// `v` normalised, or an error for `what` when it is zero.
fn unit(what: &str, value: &Value) -> mlua::Result<V3> {
    let v = finite_vector(what, value)?;
    let len = dot(v, v).sqrt();
    if !(len > 1e-6 && len.is_finite()) {
        return Err(expected(what, "a non-zero Vector", value));
    }
    Ok(scale(v, 1.0 / len))
}

/// The rotation taking +Y onto the unit vector `n`.
fn y_onto(n: V3) -> Quat {
    let c = n[1];
    if c < -0.999_999 {
        return [1.0, 0.0, 0.0, 0.0]; // half a turn about X
    }
    // Half-way quaternion: axis Y × n, angle acos(c).
    let axis = cross([0.0, 1.0, 0.0], n);
    let w = 1.0 + c;
    let len = (dot(axis, axis) + w * w).sqrt();
    [axis[0] / len, axis[1] / len, axis[2] / len, w / len]
}

/// `Renderable.Plane(normal, offset)`.
fn plane_part(lua: &Lua, normal: &Value, offset: &Value) -> mlua::Result<PartState> {
    const WHAT: &str = "Renderable.Plane";
    let n = unit(&format!("{WHAT} normal"), normal)?;
    let d = finite_number(&format!("{WHAT} offset"), offset)? as f32;
    if d.abs() > client_sdk::validate::MAX_COORDINATE / 2.0 {
        return Err(expected(
            &format!("{WHAT} offset"),
            &format!(
                "a distance within ±{}",
                client_sdk::validate::MAX_COORDINATE / 2.0
            ),
            offset,
        ));
    }
    let part = PartState::new(PartShape::Cube);
    part.set_name("Plane".into());
    part.resize(lua, WHAT, [PLANE_EXTENT, PLANE_DEPTH, PLANE_EXTENT])?;
    part.store_cframe(CFrame {
        position: scale(n, d - PLANE_DEPTH / 2.0),
        rotation: y_onto(n),
    });
    part.set_anchor_on_add(true);
    Ok(part)
}

/// One bounding plane of a brush: unit normal and offset (`normal · x ≤ offset` inside).
type Bound = (V3, f32);

fn bounds(what: &str, planes: &Value) -> mlua::Result<Vec<Bound>> {
    let Value::Table(list) = planes else {
        return Err(expected(
            what,
            "an array of {Normal = Vector, Offset = number}",
            planes,
        ));
    };
    let mut out = Vec::new();
    for (i, entry) in list.clone().sequence_values::<Value>().enumerate() {
        let entry = entry?;
        let at = format!("{what} planes[{}]", i + 1);
        let Value::Table(t) = &entry else {
            return Err(expected(
                &at,
                "a table {Normal = Vector, Offset = number}",
                &entry,
            ));
        };
        let n = unit(&format!("{at}.Normal"), &t.get::<Value>("Normal")?)?;
        let d = finite_number(&format!("{at}.Offset"), &t.get::<Value>("Offset")?)? as f32;
        if d.abs() > client_sdk::validate::MAX_SIZE {
            return Err(mlua::Error::runtime(format!(
                "{at}.Offset must be within ±{}, got {d}",
                client_sdk::validate::MAX_SIZE
            )));
        }
        out.push((n, d));
    }
    if out.len() < 4 {
        return Err(mlua::Error::runtime(format!(
            "{what}: a solid needs at least 4 planes, got {}",
            out.len()
        )));
    }
    Ok(out)
}

/// The corners of the solid `planes` bound and its faces as triangles (0-based), or why
/// there is none.
pub fn brush_mesh(planes: &[Bound]) -> Result<(Vec<V3>, Vec<[u32; 3]>), String> {
    let reach = planes.iter().fold(1.0f32, |m, (_, d)| m.max(d.abs()));
    let eps = 1e-5 * reach;
    let inside = |p: V3| planes.iter().all(|(n, d)| dot(*n, p) <= d + eps);
    let mut corners: Vec<V3> = Vec::new();
    for i in 0..planes.len() {
        for j in i + 1..planes.len() {
            for k in j + 1..planes.len() {
                let ((a, da), (b, db), (c, dc)) = (planes[i], planes[j], planes[k]);
                let bc = cross(b, c);
                let det = dot(a, bc);
                if det.abs() < 1e-6 {
                    continue; // two of them parallel, or all three through one line
                }
                // p = (da (b × c) + db (c × a) + dc (a × b)) / det
                let p: V3 = std::array::from_fn(|m| {
                    (da * bc[m] + db * cross(c, a)[m] + dc * cross(a, b)[m]) / det
                });
                if p.iter().all(|v| v.is_finite())
                    && inside(p)
                    && !corners.iter().any(|q| {
                        let e = sub(*q, p);
                        dot(e, e) <= eps * eps
                    })
                {
                    corners.push(p);
                }
            }
        }
    }
    if corners.len() < 4 {
        return Err(format!(
            "the planes bound no solid ({} corners: they leave it empty, flat or open)",
            corners.len()
        ));
    }
    // Each plane touching at least 3 corners is a face: its corners in order around it,
    // fanned into triangles. Every edge of a closed solid is shared by exactly two faces;
    // an open region (unbounded) leaves edges with one.
    let mut triangles = Vec::new();
    let mut edges: Vec<(u32, u32, u32)> = Vec::new();
    for (n, d) in planes {
        let mut on: Vec<u32> = (0..corners.len() as u32)
            .filter(|&i| (dot(*n, corners[i as usize]) - d).abs() <= eps * 10.0)
            .collect();
        if on.len() < 3 {
            continue;
        }
        let centre = scale(
            on.iter().fold([0.0; 3], |s, &i| {
                std::array::from_fn(|m| s[m] + corners[i as usize][m])
            }),
            1.0 / on.len() as f32,
        );
        let u = {
            let e = sub(corners[on[0] as usize], centre);
            scale(e, 1.0 / dot(e, e).sqrt().max(f32::MIN_POSITIVE))
        };
        let v = cross(*n, u);
        let angle = |i: &u32| {
            let e = sub(corners[*i as usize], centre);
            dot(e, v).atan2(dot(e, u))
        };
        on.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
        for w in 1..on.len() - 1 {
            triangles.push([on[0], on[w], on[w + 1]]);
        }
        for w in 0..on.len() {
            let (a, b) = (on[w], on[(w + 1) % on.len()]);
            let key = (a.min(b), a.max(b));
            match edges.iter_mut().find(|e| (e.0, e.1) == key) {
                Some(e) => e.2 += 1,
                None => edges.push((key.0, key.1, 1)),
            }
        }
    }
    if let Some(e) = edges.iter().find(|e| e.2 != 2) {
        return Err(format!(
            "the planes bound no closed solid (the edge from {:?} to {:?} has {} faces)",
            corners[e.0 as usize], corners[e.1 as usize], e.2
        ));
    }
    // Volume: the tetrahedra from corner 0 to every face triangle tile a convex solid
    // (faces through corner 0 add nothing), whatever each triangle's winding; a flat set of
    // corners has none.
    let volume: f32 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| sub(corners[i as usize], corners[0]));
            dot(a, cross(b, c)).abs() / 6.0
        })
        .sum();
    if volume <= eps * eps * eps {
        return Err(format!(
            "the planes bound no solid (its {} corners are coplanar)",
            corners.len()
        ));
    }
    Ok((corners, triangles))
}

/// `Renderable.Brush(planes)`.
fn brush_part(planes: &Value) -> mlua::Result<PartState> {
    const WHAT: &str = "Renderable.Brush";
    let bounds = bounds(WHAT, planes)?;
    let (corners, triangles) =
        brush_mesh(&bounds).map_err(|e| mlua::Error::runtime(format!("{WHAT}: {e}")))?;
    let part = PartState::mesh(corners, triangles, CFrame::IDENTITY);
    part.set_name("Brush".into());
    part.set_anchor_on_add(true);
    Ok(part)
}

/// Adds `Plane` and `Brush` to the Renderable module.
pub fn add_constructors(lua: &Lua, renderable: &Table) -> mlua::Result<()> {
    renderable.set(
        "Plane",
        lua.create_function(|lua, (normal, offset): (Value, Value)| {
            super::part::part_ud(lua, &std::rc::Rc::new(plane_part(lua, &normal, &offset)?))
        })?,
    )?;
    renderable.set(
        "Brush",
        lua.create_function(|lua, planes: Value| {
            super::part::part_ud(lua, &std::rc::Rc::new(brush_part(&planes)?))
        })?,
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(h: f32) -> Vec<Bound> {
        let mut out = Vec::new();
        for k in 0..3 {
            for s in [1.0, -1.0] {
                let mut n = [0.0; 3];
                n[k] = s;
                out.push((n, h));
            }
        }
        out
    }

    #[test]
    fn a_cube_of_six_planes_has_eight_corners_and_twelve_triangles() {
        let (corners, triangles) = brush_mesh(&cube(1.0)).unwrap();
        assert_eq!(corners.len(), 8);
        assert!(corners.iter().all(|c| c.iter().all(|v| v.abs() == 1.0)));
        assert_eq!(triangles.len(), 12);
    }

    #[test]
    fn a_cut_corner_adds_a_triangle_face() {
        let mut planes = cube(1.0);
        let k = 1.0 / 3f32.sqrt();
        planes.push(([k, k, k], 2.5 * k));
        let (corners, _) = brush_mesh(&planes).unwrap();
        // 7 cube corners and 3 on the cut.
        assert_eq!(corners.len(), 10, "{corners:?}");
        assert!(!corners.iter().any(|c| c == &[1.0, 1.0, 1.0]));
    }

    #[test]
    fn open_empty_and_flat_sets_are_refused() {
        let mut open = cube(1.0);
        open.remove(0); // no +X face
        assert!(brush_mesh(&open).is_err());
        let mut empty = cube(1.0);
        empty.push(([1.0, 0.0, 0.0], -2.0));
        assert!(brush_mesh(&empty).is_err());
        assert!(brush_mesh(&cube(0.0)).is_err());
        let mut slab = cube(1.0);
        slab[2].1 = 0.0; // y ≤ 0 and -y ≤ 0
        slab[3].1 = 0.0;
        assert!(brush_mesh(&slab).unwrap_err().contains("coplanar"));
    }

    #[test]
    fn y_onto_turns_up_into_the_normal() {
        let k = 1.0 / 2f32.sqrt();
        for n in [
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [k, k, 0.0],
            [0.0, 0.0, 1.0],
        ] {
            let r = crate::values::rotation::rotate(y_onto(n), [0.0, 1.0, 0.0]);
            for m in 0..3 {
                assert!((r[m] - n[m]).abs() < 1e-6, "{n:?} → {r:?}");
            }
        }
    }
}
