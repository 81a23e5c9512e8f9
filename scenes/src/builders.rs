//! The scenes themselves: the floors, stacks, pyramids, piles and launched bodies that the
//! accuracy and stability benches, the `ipc` bench and the integration tests all build.
//! Positions and sizes are computed here and only here, so the same arguments always give
//! the same world to the last bit.

use shm_layout::{ObjectProp, Pose, Shape};

use crate::target::SceneTarget;

/// What a builder returns: the handles of the target, or its error.
pub type Built<T, V> = Result<V, <T as SceneTarget>::Error>;

/// Contact gap a resting pair keeps at HitBoxQuality `quality`: none at any quality (the
/// planes give colliders no contact skin; resting bodies touch).
pub fn pair_gap(quality: u32) -> f32 {
    let _ = quality;
    0.0
}

/// A cube of side `side`.
pub fn cube(side: f32) -> Shape {
    Shape::Cube {
        size: [side, side, side],
    }
}

/// A ball of radius 0.5 at `at`, with `props`.
pub fn ball<T: SceneTarget + ?Sized>(
    target: &mut T,
    at: [f32; 3],
    props: &[ObjectProp],
) -> Built<T, T::Handle> {
    target.add(Shape::Sphere { radius: 0.5 }, Pose::at(at), props)
}

/// An anchored box of `size` at `pose`: `Anchored(true)`, then `props`.
pub fn anchored_box<T: SceneTarget + ?Sized>(
    target: &mut T,
    size: [f32; 3],
    pose: Pose,
    props: &[ObjectProp],
) -> Built<T, T::Handle> {
    let mut all = vec![ObjectProp::Anchored(true)];
    all.extend_from_slice(props);
    target.add(Shape::Cube { size }, pose, &all)
}

/// An anchored box of `size` whose top face is centred at `top`.
pub fn slab<T: SceneTarget + ?Sized>(
    target: &mut T,
    top: [f32; 3],
    size: [f32; 3],
    props: &[ObjectProp],
) -> Built<T, T::Handle> {
    let [x, y, z] = top;
    anchored_box(target, size, Pose::at([x, y - size[1] / 2.0, z]), props)
}

/// The usual floor: an anchored `width` × 1 × `width` slab centred on the origin whose top
/// face is y = 0.
pub fn floor<T: SceneTarget + ?Sized>(
    target: &mut T,
    width: f32,
    props: &[ObjectProp],
) -> Built<T, T::Handle> {
    slab(target, [0.0; 3], [width, 1.0, width], props)
}

/// A column of `n` cubes of `side` standing on a floor whose top is at `base[1]`, centred on
/// (`base[0]`, `base[2]`). Each cube is placed at its rest height (`gap` apart, see
/// [`pair_gap`]) and offset along x by +`jitter` and −`jitter` alternately; cube `i` gets
/// `props(i)`. Returns the cubes bottom to top.
pub fn column<T: SceneTarget + ?Sized>(
    target: &mut T,
    base: [f32; 3],
    side: f32,
    n: usize,
    jitter: f32,
    gap: f32,
    mut props: impl FnMut(usize) -> Vec<ObjectProp>,
) -> Built<T, Vec<T::Handle>> {
    (0..n)
        .map(|i| {
            let y = base[1] + side / 2.0 + gap + i as f32 * (side + gap);
            let dx = if i % 2 == 0 { jitter } else { -jitter };
            target.add(cube(side), Pose::at([base[0] + dx, y, base[2]]), &props(i))
        })
        .collect()
}

/// A pyramid of unit cubes on a floor whose top is y = 0: a row of `base` cubes along x
/// centred on the origin, each row above one cube shorter. Rows are `gap` apart (their rest
/// height, see [`pair_gap`]); neighbours in a row are 0.03 further apart than that, so they
/// do not touch. Returns the cubes row by row from the bottom.
pub fn pyramid<T: SceneTarget + ?Sized>(
    target: &mut T,
    base: usize,
    gap: f32,
) -> Built<T, Vec<T::Handle>> {
    let pitch = 1.0 + gap + 0.03;
    let mut boxes = Vec::new();
    for row in 0..base {
        let count = base - row;
        let x0 = -(count as f32 - 1.0) * pitch / 2.0;
        let y = 0.5 + gap + row as f32 * (1.0 + gap);
        for i in 0..count {
            boxes.push(target.add(cube(1.0), Pose::at([x0 + i as f32 * pitch, y, 0.0]), &[])?);
        }
    }
    Ok(boxes)
}

/// A 3 × 3 × 3 pile of unit cubes 0.75 apart on every axis, the lowest layer's centres at
/// y = 0.5: each cube overlaps its neighbours by 25 %.
pub fn overlapping_pile<T: SceneTarget + ?Sized>(target: &mut T) -> Built<T, Vec<T::Handle>> {
    let pitch = 0.75;
    let mut boxes = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                let p = [i as f32 * pitch, 0.5 + j as f32 * pitch, k as f32 * pitch];
                boxes.push(target.add(cube(1.0), Pose::at(p), &[])?);
            }
        }
    }
    Ok(boxes)
}

/// An anchored wall 0.1 thick and 10 × 10 across whose front face is the plane x = 0:
/// `Anchored(true)`, then `props`.
pub fn thin_wall<T: SceneTarget + ?Sized>(
    target: &mut T,
    props: &[ObjectProp],
) -> Built<T, T::Handle> {
    anchored_box(target, [0.1, 10.0, 10.0], Pose::at([0.05, 0.0, 0.0]), props)
}

/// A 0.5 cube at (`x`, 0, 0) launched along +x at `speed`: `props`, then the velocity.
pub fn launched_box<T: SceneTarget + ?Sized>(
    target: &mut T,
    x: f32,
    speed: f32,
    props: &[ObjectProp],
) -> Built<T, T::Handle> {
    let mut all = props.to_vec();
    all.push(ObjectProp::Velocity([speed, 0.0, 0.0]));
    target.add(cube(0.5), Pose::at([x, 0.0, 0.0]), &all)
}

/// A resting column and a dropped ball, at any scale.
pub struct StackAndBall<H> {
    /// The column's cubes, bottom to top.
    pub boxes: Vec<H>,
    /// The ball.
    pub ball: H,
}

/// On an anchored floor `100·side` wide and `side` thick whose top face is centred at
/// `origin`: a column of `n` cubes of `side` (no jitter, `gap` apart, each with
/// `box_props`) at the centre, and a ball of the same diameter `drop` above the floor, ten
/// sides along x.
pub fn stack_and_ball<T: SceneTarget + ?Sized>(
    target: &mut T,
    origin: [f32; 3],
    side: f32,
    n: usize,
    drop: f32,
    gap: f32,
    box_props: &[ObjectProp],
) -> Built<T, StackAndBall<T::Handle>> {
    let [ox, oy, oz] = origin;
    slab(target, origin, [100.0 * side, side, 100.0 * side], &[])?;
    let boxes = column(target, origin, side, n, 0.0, gap, |_| box_props.to_vec())?;
    let ball = target.add(
        Shape::Sphere { radius: side / 2.0 },
        Pose::at([ox + 10.0 * side, oy + drop, oz]),
        &[],
    )?;
    Ok(StackAndBall { boxes, ball })
}

/// The determinism scene: on a floor (top y = 0), a base-6 pyramid of unit cubes and 12
/// bouncy balls thrown at it from both sides, every object at HitBoxQuality 4 (free
/// rotation, CCD): one island of contacts, rotations, bounces and friction, all of which
/// must come out bit-identical in every run. Returns the cubes, then the balls.
pub fn determinism_scene<T: SceneTarget + ?Sized>(target: &mut T) -> Built<T, Vec<T::Handle>> {
    let q = ObjectProp::HitBoxQuality(4);
    floor(target, 60.0, &[q])?;
    let mut out = Vec::new();
    let pitch = 1.03;
    for row in 0..6 {
        let count = 6 - row;
        let x0 = -(count as f32 - 1.0) * pitch / 2.0;
        for i in 0..count {
            let p = [x0 + i as f32 * pitch, 0.5 + row as f32, 0.0];
            out.push(target.add(cube(1.0), Pose::at(p), &[q])?);
        }
    }
    for i in 0..12 {
        let side = if i % 2 == 0 { -1.0 } else { 1.0 };
        let (x, y, z) = (side * 8.0, 2.0 + i as f32 * 0.7, (i as f32 - 5.5) * 0.15);
        let props = [
            q,
            ObjectProp::Bounciness(0.5),
            ObjectProp::Velocity([-side * 12.0, 3.0, 0.3 * side]),
            ObjectProp::AngularVelocity([0.0, 2.0, side]),
        ];
        out.push(target.add(Shape::Sphere { radius: 0.3 }, Pose::at([x, y, z]), &props)?);
    }
    Ok(out)
}

/// Cubes per column of a [`pile`].
pub const PILE_HEIGHT: usize = 5;
/// Distance between the columns of a [`pile`] (cubes are 1 wide: columns do not touch).
const PILE_SPACING: f32 = 1.25;
/// Distance between the bodies of [`free_bodies`].
const FREE_SPACING: f32 = 3.0;

/// `bodies` unit cubes in columns of [`PILE_HEIGHT`] on a square grid, resting on an
/// anchored floor one unit wider than the grid on every side: the settled world most of a
/// game level is. Returns the floor first, then the cubes.
pub fn pile<T: SceneTarget + ?Sized>(target: &mut T, bodies: usize) -> Built<T, Vec<T::Handle>> {
    let columns = bodies.div_ceil(PILE_HEIGHT);
    let side = (columns as f64).sqrt().ceil() as usize;
    let width = side as f32 * PILE_SPACING;
    let mut out = Vec::with_capacity(bodies + 1);
    out.push(slab(
        target,
        [width / 2.0, 0.0, width / 2.0],
        [width + 2.0, 1.0, width + 2.0],
        &[],
    )?);
    for i in 0..bodies {
        let (column, layer) = (i / PILE_HEIGHT, i % PILE_HEIGHT);
        let x = (column % side) as f32 * PILE_SPACING + 0.5;
        let z = (column / side) as f32 * PILE_SPACING + 0.5;
        out.push(target.add(cube(1.0), Pose::at([x, 0.5 + layer as f32, z]), &[])?);
    }
    Ok(out)
}

/// `bodies` unit cubes on a sparse cubic grid, each with a random (but always the same)
/// velocity and angular velocity: with gravity off, everything awake and moving, few
/// contacts.
pub fn free_bodies<T: SceneTarget + ?Sized>(
    target: &mut T,
    bodies: usize,
) -> Built<T, Vec<T::Handle>> {
    let side = (bodies as f64).cbrt().ceil() as usize;
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    (0..bodies)
        .map(|i| {
            let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
            let props = [
                ObjectProp::Velocity([rng.unit(), rng.unit(), rng.unit()]),
                ObjectProp::AngularVelocity([rng.unit(), rng.unit(), rng.unit()]),
            ];
            target.add(
                cube(1.0),
                Pose::at([x as f32, y as f32, z as f32].map(|c| c * FREE_SPACING)),
                &props,
            )
        })
        .collect()
}

/// xorshift64*: deterministic velocities without a dependency.
struct Rng(u64);

impl Rng {
    /// Uniform in [-1, 1).
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40;
        bits as f32 / (1u64 << 23) as f32 - 1.0
    }
}

/// An anchored open box for debris scenes: a floor whose top is y = 0 spanning `width` ×
/// `width` inside, and four walls 1 thick and `height` tall around it. Returns floor, then
/// walls (−x, +x, −z, +z).
pub fn container<T: SceneTarget + ?Sized>(
    target: &mut T,
    width: f32,
    height: f32,
) -> Built<T, Vec<T::Handle>> {
    let outer = width + 2.0;
    let mut all = vec![anchored_box(
        target,
        [outer, 1.0, outer],
        Pose::at([0.0, -0.5, 0.0]),
        &[],
    )?];
    let y = height / 2.0;
    let off = width / 2.0 + 0.5;
    for (at, size) in [
        ([-off, y, 0.0], [1.0, height, outer]),
        ([off, y, 0.0], [1.0, height, outer]),
        ([0.0, y, -off], [outer, height, 1.0]),
        ([0.0, y, off], [outer, height, 1.0]),
    ] {
        all.push(anchored_box(target, size, Pose::at(at), &[])?);
    }
    Ok(all)
}

/// Where [`debris`] puts `n` unit cubes: columns `per_row` × `per_row` spaced 1.25 apart,
/// centred on the y axis, layers 1.25 apart from y = `base` up. Also the inner width of a
/// container that holds the columns with 0.5 to spare on each side.
pub fn debris_layout(n: usize, per_row: usize, base: f32) -> (Vec<[f32; 3]>, f32) {
    let spacing = 1.25;
    let span = (per_row - 1) as f32 * spacing;
    let positions = (0..n)
        .map(|i| {
            let (col, layer) = (i % (per_row * per_row), i / (per_row * per_row));
            let (cx, cz) = (col % per_row, col / per_row);
            [
                cx as f32 * spacing - span / 2.0,
                base + layer as f32 * spacing,
                cz as f32 * spacing - span / 2.0,
            ]
        })
        .collect();
    (positions, span + 1.0 + 1.0)
}

/// `n` unit cubes laid out by [`debris_layout`] (falling debris), each with `props`.
pub fn debris<T: SceneTarget + ?Sized>(
    target: &mut T,
    n: usize,
    per_row: usize,
    base: f32,
    props: &[ObjectProp],
) -> Built<T, Vec<T::Handle>> {
    debris_layout(n, per_row, base)
        .0
        .into_iter()
        .map(|at| target.add(cube(1.0), Pose::at(at), props))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Spawn;

    fn record<V>(build: impl FnOnce(&mut Vec<Spawn>) -> Built<Vec<Spawn>, V>) -> Vec<Spawn> {
        let mut spawns = Vec::new();
        let Ok(_) = build(&mut spawns);
        spawns
    }

    #[test]
    fn piles_and_free_bodies_have_the_asked_body_count() {
        for n in [1, 7, 100, 1000] {
            let pile = record(|t| pile(t, n));
            assert_eq!(pile.len(), n + 1, "pile has a floor on top");
            assert_eq!(record(|t| free_bodies(t, n)).len(), n);
        }
    }

    #[test]
    fn random_velocities_stay_in_range() {
        let mut rng = Rng(1);
        for _ in 0..10_000 {
            let v = rng.unit();
            assert!((-1.0..1.0).contains(&v), "{v}");
        }
    }

    #[test]
    fn a_column_rests_gap_apart_on_its_floor() {
        let spawns = record(|t| column(t, [0.0, 2.0, 0.0], 1.0, 3, 0.1, 0.02, |_| vec![]));
        let y: Vec<f32> = spawns.iter().map(|s| s.pose.position[1]).collect();
        assert_eq!(y, [2.52, 3.54, 4.56]);
        let x: Vec<f32> = spawns.iter().map(|s| s.pose.position[0]).collect();
        assert_eq!(x, [0.1, -0.1, 0.1]);
    }

    #[test]
    fn a_pyramid_of_base_twenty_has_210_boxes_whose_neighbours_do_not_touch() {
        let spawns = record(|t| pyramid(t, 20, pair_gap(1)));
        assert_eq!(spawns.len(), 210);
        // Rows 1 apart from 0.5 up (no gap), neighbours 1.03 apart: to the last bit.
        let x0 = -19.0 * 1.03 / 2.0;
        for (i, s) in spawns[..20].iter().enumerate() {
            assert_eq!(s.pose.position, [x0 + i as f32 * 1.03, 0.5, 0.0]);
        }
        assert_eq!(spawns[20].pose.position[1], 0.5 + 1.0);
    }

    #[test]
    fn properties_keep_their_order() {
        let q = ObjectProp::HitBoxQuality(4);
        let wall = record(|t| thin_wall(t, &[q]));
        assert_eq!(wall[0].props, [ObjectProp::Anchored(true), q]);
        let launched = record(|t| launched_box(t, -30.0, 400.0, &[q]));
        assert_eq!(
            launched[0].props,
            [q, ObjectProp::Velocity([400.0, 0.0, 0.0])]
        );
    }
}
