// The GPU plane step (DeferGpu): forces, the spatial-hash broadphase (count, scatter; the
// prefix sum is scan.wgsl), contact resolution + integration, and the pair list used by
// the tests. One body per invocation; state ping-pongs between `state_in` and `state_out`.
//
// Bodies are spheres or axis-aligned boxes (a non-sphere keeps the orientation it had when
// it reached the GPU, and collides as the world box around its rotated Size).

const WG: u32 = 128u;

const F_ALIVE: u32 = 1u;
const F_DYNAMIC: u32 = 2u;
const F_COLLIDE: u32 = 4u;
const F_SPHERE: u32 = 8u;
const F_LARGE: u32 = 16u;
// Translation locks X, Y, Z: bits 5, 6, 7.
const F_LOCK_X: u32 = 32u;

struct State {
    pos: vec4<f32>,
    rot: vec4<f32>,
    vel: vec4<f32>,
    ang: vec4<f32>,
}

struct Param {
    // xyz: half extents of the world box; w: sphere radius (0 for boxes).
    half: vec4<f32>,
    // xyz: the body's own acceleration (ImpulseDirection + ConstantForce / mass); w: 1 / mass
    // (0 for anchored bodies).
    accel: vec4<f32>,
    // x: Bounciness, y: Friction, z: 5 / (2 r) for spheres (angular response), w: unused.
    mat: vec4<f32>,
    // x: flags, y: collision-group bit, z: the group's mask, w: unused.
    bits: vec4<u32>,
}

struct Env {
    // xyz: gravity · h; w: h (substep length).
    gravity_h: vec4<f32>,
    // xyz: plane ConstantForce; w: Buoyancy.
    force: vec4<f32>,
    // x: linear keep per tick, y: angular keep per substep, z: Drag, w: tick dt.
    damp: vec4<f32>,
    // x: MaxLinearSpeed, y: MaxAngularSpeed, z: RestThreshold, w: cell size.
    limits: vec4<f32>,
    // x: bodies, y: hash table size (power of two), z: large bodies, w: substeps.
    counts: vec4<u32>,
    // x: 1 = brute-force pairs, y: pair capacity, zw: unused.
    mode: vec4<u32>,
}

@group(0) @binding(0) var<uniform> env: Env;
@group(0) @binding(1) var<storage, read> params: array<Param>;
@group(0) @binding(2) var<storage, read_write> dv: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> state_in: array<State>;
@group(0) @binding(4) var<storage, read_write> state_out: array<State>;
// [0, T): bodies per cell; [T, 2T): scatter cursors; 2T: pair count.
@group(0) @binding(5) var<storage, read_write> atoms: array<atomic<u32>>;
// [0, T): first sorted entry of each bucket (exclusive prefix sum); from T: the hashed
// bodies sorted by bucket, four u32 each (the body, then its cell x, y, z).
@group(0) @binding(6) var<storage, read_write> index: array<u32>;
// Large bodies (anchored ones bigger than a cell) first, then the pair list (2 u32 each).
@group(0) @binding(7) var<storage, read_write> lists: array<u32>;

fn flags(i: u32) -> u32 {
    return params[i].bits.x;
}

fn cell_of(p: vec3<f32>) -> vec3<i32> {
    return vec3<i32>(floor(p / env.limits.w));
}

// The bucket of a cell: x is added to a hash of the row (y, z), so the three cells of a row
// that a body's neighbourhood spans sit in consecutive buckets, and their bodies in one run of
// the sorted entries (9 runs per neighbourhood instead of 27 scattered buckets).
fn hash_cell(c: vec3<i32>) -> u32 {
    let row = (u32(c.y) * 19349663u) ^ (u32(c.z) * 83492791u);
    return (u32(c.x) + row) & (env.counts.y - 1u);
}

// One past the last sorted entry of bucket b.
fn bucket_end(b: u32) -> u32 {
    return index[b] + atomicLoad(&atoms[b]);
}

// Entry k of the bodies sorted by bucket: `index[t + 4k]` is the body, the next three its
// cell. An entry is in the row (y, z) of `home` within one cell of it along x: a body that
// only shares a bucket (another row, or farther along x) is skipped without reading its
// state or parameters, and every body is met once.
fn entry_near(e: u32, home: vec3<i32>) -> bool {
    let dx = i32(index[e + 1u]) - home.x;
    return index[e + 2u] == u32(home.y) && index[e + 3u] == u32(home.z) && dx >= -1 && dx <= 1;
}

// The sorted entries [first, last) of the q-th run of the row of `home` (cells x - 1, x,
// x + 1): one run when their buckets do not wrap around the table's end, else one run per
// bucket (q = 0, 1, 2). Empty past the last run.
fn row_run(home: vec3<i32>, q: u32) -> vec2<u32> {
    let mask = env.counts.y - 1u;
    let lo = hash_cell(home - vec3<i32>(1, 0, 0));
    if (lo + 2u == ((lo + 2u) & mask)) {
        if (q > 0u) {
            return vec2<u32>(0u, 0u);
        }
        return vec2<u32>(index[lo], bucket_end(lo + 2u));
    }
    let b = (lo + q) & mask;
    return vec2<u32>(index[b], bucket_end(b));
}

fn hashed(i: u32) -> bool {
    let f = flags(i);
    return (f & F_ALIVE) != 0u && (f & F_COLLIDE) != 0u && (f & F_LARGE) == 0u;
}

@compute @workgroup_size(WG)
fn forces(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= env.counts.x) {
        return;
    }
    let p = params[i];
    if ((p.bits.x & (F_ALIVE | F_DYNAMIC)) != (F_ALIVE | F_DYNAMIC)) {
        dv[i] = vec4<f32>(0.0);
        return;
    }
    let dt = env.damp.w;
    let inv_mass = p.accel.w;
    let v0 = state_in[i].vel.xyz;
    let a = vec3<f32>(0.0, env.force.w, 0.0) + p.accel.xyz + env.force.xyz * inv_mass;
    var v = v0 + a * dt;
    // Drag F = -Drag·|v|·v, backward Euler in closed form (never reverses a velocity).
    let c_dt = env.damp.z * inv_mass * dt;
    let s = length(v);
    if (s > 0.0 && c_dt > 0.0) {
        let s_new = 2.0 * s / (1.0 + sqrt(1.0 + 4.0 * c_dt * s));
        v = v * (s_new / s);
    }
    v = v * env.damp.x;
    dv[i] = vec4<f32>(lock(v - v0, p.bits.x), 0.0);
}

fn lock(v: vec3<f32>, f: u32) -> vec3<f32> {
    var r = v;
    if ((f & F_LOCK_X) != 0u) { r.x = 0.0; }
    if ((f & (F_LOCK_X << 1u)) != 0u) { r.y = 0.0; }
    if ((f & (F_LOCK_X << 2u)) != 0u) { r.z = 0.0; }
    return r;
}

@compute @workgroup_size(WG)
fn count(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= env.counts.x || !hashed(i)) {
        return;
    }
    atomicAdd(&atoms[hash_cell(cell_of(state_in[i].pos.xyz))], 1u);
}

@compute @workgroup_size(WG)
fn scatter(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= env.counts.x || !hashed(i)) {
        return;
    }
    let t = env.counts.y;
    let c = cell_of(state_in[i].pos.xyz);
    let at = atomicAdd(&atoms[t + hash_cell(c)], 1u);
    let e = t + 4u * at;
    index[e] = i;
    index[e + 1u] = u32(c.x);
    index[e + 2u] = u32(c.y);
    index[e + 3u] = u32(c.z);
}

// A contact between i and j: normal from j toward i and depth (> 0 when they overlap).
struct Contact {
    n: vec3<f32>,
    depth: f32,
}

fn box_box(d: vec3<f32>, h: vec3<f32>) -> Contact {
    // d = pi - pj, h = summed half extents.
    let o = h - abs(d);
    var c: Contact;
    c.depth = -1.0;
    if (o.x <= 0.0 || o.y <= 0.0 || o.z <= 0.0) {
        return c;
    }
    if (o.x <= o.y && o.x <= o.z) {
        c.n = vec3<f32>(select(-1.0, 1.0, d.x >= 0.0), 0.0, 0.0);
        c.depth = o.x;
    } else if (o.y <= o.z) {
        c.n = vec3<f32>(0.0, select(-1.0, 1.0, d.y >= 0.0), 0.0);
        c.depth = o.y;
    } else {
        c.n = vec3<f32>(0.0, 0.0, select(-1.0, 1.0, d.z >= 0.0));
        c.depth = o.z;
    }
    return c;
}

// Sphere at `s` with radius r against the box of half extents h at `b`: normal toward the
// sphere.
fn sphere_box(s: vec3<f32>, r: f32, b: vec3<f32>, h: vec3<f32>) -> Contact {
    let d = s - b;
    let q = clamp(d, -h, h);
    let e = d - q;
    let l = length(e);
    var c: Contact;
    c.depth = -1.0;
    if (l > 0.0) {
        if (l < r) {
            c.n = e / l;
            c.depth = r - l;
        }
        return c;
    }
    // The centre is inside the box: push out along the shallowest axis.
    return box_box(d, h + vec3<f32>(r));
}

fn contact(i: u32, pi: vec3<f32>, j: u32, pj: vec3<f32>) -> Contact {
    let a = params[i];
    let b = params[j];
    let sa = (a.bits.x & F_SPHERE) != 0u;
    let sb = (b.bits.x & F_SPHERE) != 0u;
    if (sa && sb) {
        let d = pi - pj;
        let l = length(d);
        var c: Contact;
        c.depth = a.half.w + b.half.w - l;
        c.n = select(vec3<f32>(0.0, 1.0, 0.0), d / l, l > 0.0);
        return c;
    }
    if (sa) {
        return sphere_box(pi, a.half.w, pj, b.half.xyz);
    }
    if (sb) {
        var c = sphere_box(pj, b.half.w, pi, a.half.xyz);
        c.n = -c.n;
        return c;
    }
    return box_box(pi - pj, a.half.xyz + b.half.xyz);
}

fn may_touch(i: u32, j: u32) -> bool {
    if (i == j) {
        return false;
    }
    let a = params[i].bits;
    let b = params[j].bits;
    if ((b.x & (F_ALIVE | F_COLLIDE)) != (F_ALIVE | F_COLLIDE)) {
        return false;
    }
    return (a.y & b.z) != 0u && (b.y & a.z) != 0u;
}

// Velocity of j at the start of this substep's contact phase (forces and gravity applied).
fn predicted_velocity(j: u32) -> vec3<f32> {
    let p = params[j];
    let v = state_in[j].vel.xyz;
    if ((p.bits.x & F_DYNAMIC) == 0u) {
        return v;
    }
    return v + lock(dv[j].xyz / f32(env.counts.w) + env.gravity_h.xyz, p.bits.x);
}

fn predicted_angular(j: u32) -> vec3<f32> {
    let p = params[j];
    if ((p.bits.x & (F_DYNAMIC | F_SPHERE)) != (F_DYNAMIC | F_SPHERE)) {
        return vec3<f32>(0.0);
    }
    return state_in[j].ang.xyz * env.damp.y;
}

// Velocity and position changes of one body, kept per world axis and sign as the largest
// push each way (not summed): a box landing on four boxes is pushed up once, not four
// times, while pushes from opposite sides (a floor below, a box above) still combine.
struct Acc {
    dv_up: vec3<f32>,
    dv_down: vec3<f32>,
    dw: vec3<f32>,
    dp_up: vec3<f32>,
    dp_down: vec3<f32>,
    n: u32,
    depth: f32,
}

fn push_v(acc: ptr<function, Acc>, d: vec3<f32>) {
    (*acc).dv_up = max((*acc).dv_up, d);
    (*acc).dv_down = min((*acc).dv_down, d);
}

const SLOP: f32 = 0.002;
const BETA: f32 = 0.8;

fn touch(i: u32, pi: vec3<f32>, vi: vec3<f32>, wi: vec3<f32>, j: u32, acc: ptr<function, Acc>) {
    if (!may_touch(i, j)) {
        return;
    }
    let sj = state_in[j];
    let c = contact(i, pi, j, sj.pos.xyz);
    if (c.depth <= 0.0) {
        return;
    }
    let a = params[i];
    let b = params[j];
    let inv_i = a.accel.w;
    let inv_j = select(0.0, b.accel.w, (b.bits.x & F_DYNAMIC) != 0u);
    var share = inv_i / (inv_i + inv_j);
    var vj = predicted_velocity(j);
    // Shock propagation: of two dynamic bodies one above the other (along gravity), the
    // upper one treats the lower as immovable and the lower ignores the upper, so a stack
    // holds its layers apart within a tick instead of sagging layer by layer.
    let g = length(env.gravity_h.xyz);
    if (inv_j > 0.0 && g > 0.0) {
        let up = dot(c.n, -env.gravity_h.xyz / g);
        if (up > 0.5) {
            share = 1.0;
            // Against the lower body's velocity before this substep's gravity: a resting
            // stack then rests (v = 0 in every layer), instead of each layer lagging the
            // one below by one substep of gravity.
            vj = state_in[j].vel.xyz;
        } else if (up < -0.5) {
            share = 0.0;
        }
    }
    let wj = predicted_angular(j);
    // Contact points relative to each centre (spheres roll; boxes do not turn).
    let ri = -c.n * a.half.w;
    let rj = c.n * b.half.w;
    let vrel = vi + cross(wi, ri) - vj - cross(wj, rj);
    let vn = dot(vi - vj, c.n);
    if (vn < 0.0) {
        let e = select(0.0, max(a.mat.x, b.mat.x), -vn > env.limits.z);
        let jn = -(1.0 + e) * vn;
        var dv = share * jn * c.n;
        let vt = vrel - dot(vrel, c.n) * c.n;
        let st = length(vt);
        if (st > 1e-6) {
            let mu = sqrt(a.mat.y * b.mat.y);
            // A sphere's tangential impulse also spins it: the contact point's velocity
            // changes 3.5 times the centre's (solid sphere).
            let k = select(1.0, 3.5, (a.bits.x & F_SPHERE) != 0u);
            let change = min(st / k, mu * jn) * share;
            let dvt = -vt / st * change;
            dv += dvt;
            (*acc).dw += -a.mat.z * cross(c.n, dvt);
        }
        push_v(acc, dv);
    }
    let dp = share * BETA * max(c.depth - SLOP, 0.0) * c.n;
    (*acc).dp_up = max((*acc).dp_up, dp);
    (*acc).dp_down = min((*acc).dp_down, dp);
    (*acc).n += 1u;
    (*acc).depth = max((*acc).depth, c.depth);
}

fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(
        a.w * b.xyz + b.w * a.xyz + cross(a.xyz, b.xyz),
        a.w * b.w - dot(a.xyz, b.xyz),
    );
}

fn clamp_length(v: vec3<f32>, m: f32) -> vec3<f32> {
    let l = length(v);
    if (l > m) {
        return v * (m / l);
    }
    return v;
}

@compute @workgroup_size(WG)
fn solve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= env.counts.x) {
        return;
    }
    let s = state_in[i];
    let p = params[i];
    if ((p.bits.x & (F_ALIVE | F_DYNAMIC)) != (F_ALIVE | F_DYNAMIC)) {
        state_out[i] = s;
        return;
    }
    let h = env.gravity_h.w;
    let pi = s.pos.xyz;
    let vi = predicted_velocity(i);
    let wi = predicted_angular(i);
    var acc: Acc;
    acc.dv_up = vec3<f32>(0.0);
    acc.dv_down = vec3<f32>(0.0);
    acc.dw = vec3<f32>(0.0);
    acc.dp_up = vec3<f32>(0.0);
    acc.dp_down = vec3<f32>(0.0);
    acc.n = 0u;
    acc.depth = 0.0;
    if ((p.bits.x & F_COLLIDE) != 0u) {
        let n = env.counts.x;
        let t = env.counts.y;
        if (env.mode.x != 0u) {
            for (var j = 0u; j < n; j++) {
                touch(i, pi, vi, wi, j, &acc);
            }
        } else {
            let large = env.counts.z;
            for (var k = 0u; k < large; k++) {
                touch(i, pi, vi, wi, lists[k], &acc);
            }
            let home = cell_of(pi);
            for (var dz = -1; dz <= 1; dz++) {
                for (var dy = -1; dy <= 1; dy++) {
                    let row = home + vec3<i32>(0, dy, dz);
                    for (var q = 0u; q < 3u; q++) {
                        let run = row_run(row, q);
                        for (var k = run.x; k < run.y; k++) {
                            let e = t + 4u * k;
                            if (entry_near(e, row)) {
                                touch(i, pi, vi, wi, index[e], &acc);
                            }
                        }
                    }
                }
            }
        }
    }
    var v = lock(vi + acc.dv_up + acc.dv_down, p.bits.x);
    var w = wi + acc.dw;
    v = clamp_length(v, env.limits.x);
    w = clamp_length(w, env.limits.y);
    let dp = lock(acc.dp_up + acc.dp_down, p.bits.x);
    var out: State;
    // w: the deepest contact and the contact count, read back for the tick's figures.
    out.pos = vec4<f32>(pi + v * h + dp, acc.depth);
    var q = s.rot;
    if ((p.bits.x & F_SPHERE) != 0u) {
        let half_angle = w * (0.5 * h);
        q = normalize(quat_mul(vec4<f32>(half_angle, 1.0), q));
    } else {
        w = vec3<f32>(0.0);
    }
    out.rot = q;
    out.vel = vec4<f32>(v, f32(acc.n));
    out.ang = vec4<f32>(w, 0.0);
    state_out[i] = out;
}

// Pairs (i < j) whose shapes overlap now, appended to `lists` after the large bodies: from
// the hash grid, or by testing every pair (mode.x = 1).
fn pair(i: u32, j: u32) {
    if (j <= i || !may_touch(i, j)) {
        return;
    }
    let c = contact(i, state_in[i].pos.xyz, j, state_in[j].pos.xyz);
    if (c.depth <= 0.0) {
        return;
    }
    let at = atomicAdd(&atoms[2u * env.counts.y], 1u);
    if (at < env.mode.y) {
        let base = env.counts.z + 2u * at;
        lists[base] = i;
        lists[base + 1u] = j;
    }
}

@compute @workgroup_size(WG)
fn pairs(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let n = env.counts.x;
    if (i >= n || (flags(i) & (F_ALIVE | F_COLLIDE)) != (F_ALIVE | F_COLLIDE)) {
        return;
    }
    if (env.mode.x != 0u) {
        for (var j = 0u; j < n; j++) {
            pair(i, j);
        }
        return;
    }
    let t = env.counts.y;
    let large = env.counts.z;
    let is_large = (flags(i) & F_LARGE) != 0u;
    // A large body meets the small ones from their side (they scan the large list); large
    // pairs meet here.
    for (var k = 0u; k < large; k++) {
        let j = lists[k];
        if (is_large) {
            pair(i, j);
        } else {
            // Keep i < j ordering in the output whichever side finds the pair.
            if (j < i) {
                pair(j, i);
            } else {
                pair(i, j);
            }
        }
    }
    if (is_large) {
        return;
    }
    let home = cell_of(state_in[i].pos.xyz);
    for (var dz = -1; dz <= 1; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            let row = home + vec3<i32>(0, dy, dz);
            for (var q = 0u; q < 3u; q++) {
                let run = row_run(row, q);
                for (var k = run.x; k < run.y; k++) {
                    let e = t + 4u * k;
                    if (entry_near(e, row)) {
                        pair(i, index[e]);
                    }
                }
            }
        }
    }
}
