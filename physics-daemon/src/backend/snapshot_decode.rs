//! Decoding a snapshot body for both rapier backends: postcard into the backend's state,
//! then the backend's cross-reference checks, with a panic anywhere in between (rapier's
//! containers assume their own invariants, which edited bytes can break) turned into a
//! refusal. Nothing of the plane is touched before this returns.

use shm_layout::CommandError;

/// `body` decoded into `T` and passed through `check`; an error or a panic is the refusal
/// `refused(why)`.
pub fn decode<T: serde::de::DeserializeOwned>(
    body: &[u8],
    refused: fn(String) -> CommandError,
    check: fn(&T) -> Result<(), CommandError>,
) -> Result<T, CommandError> {
    let decoded = std::panic::catch_unwind(|| {
        let state: T = postcard::from_bytes(body)
            .map_err(|e| refused(format!("its state does not decode ({e})")))?;
        check(&state)?;
        Ok(state)
    });
    match decoded {
        Ok(result) => result,
        Err(_) => Err(refused(
            "its engine state does not hold together (edited bytes?)".to_string(),
        )),
    }
}

/// Deepest broad-phase tree a snapshot may hold. The engine refits the tree recursively
/// (one stack frame per level); balanced trees of millions of leaves are a few dozen deep.
const MAX_TREE_DEPTH: u32 = 256;

/// One node of parry's BVH as it is serialised (`BvhNode`: mins, children, maxs, data).
#[derive(serde::Deserialize)]
struct NodeOnWire<const D: usize> {
    #[serde(with = "serde_arrays")]
    _mins: [f32; D],
    children: u32,
    #[serde(with = "serde_arrays")]
    _maxs: [f32; D],
    data: u32,
}

/// The start of parry's serialised `Bvh` (the broad phase's first field): its nodes, two
/// per entry (`BvhNodeWide`).
#[derive(serde::Deserialize)]
struct TreeOnWire<const D: usize> {
    nodes: Vec<[NodeOnWire<D>; 2]>,
}

mod serde_arrays {
    //! `[f32; D]` as the fixed-size tuple serde writes for parry's vectors.
    use serde::de::{Deserializer, Error, SeqAccess, Visitor};

    pub fn deserialize<'de, Dz: Deserializer<'de>, const D: usize>(
        d: Dz,
    ) -> Result<[f32; D], Dz::Error> {
        struct V<const D: usize>;
        impl<'de, const D: usize> Visitor<'de> for V<D> {
            type Value = [f32; D];
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "{D} floats")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f32; D], A::Error> {
                let mut out = [0.0; D];
                for (i, v) in out.iter_mut().enumerate() {
                    *v = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(i, &self))?;
                }
                Ok(out)
            }
        }
        d.deserialize_tuple(D, V::<D>)
    }
}

/// Checks that a decoded broad phase (serialised again here, `D` = 2 or 3 dimensions) holds
/// a tree: every inner node's children in range, no node reached twice (a loop would send
/// the engine's recursive refit into a stack overflow, which no unwinding can contain),
/// leaf counts that add up, and a bounded depth.
pub fn check_broad_phase<B: serde::Serialize, const D: usize>(
    broad_phase: &B,
) -> Result<(), String> {
    let bytes = postcard::to_allocvec(broad_phase).map_err(|e| e.to_string())?;
    let (tree, _): (TreeOnWire<D>, _) = postcard::take_from_bytes(&bytes)
        .map_err(|e| format!("its broad phase does not decode ({e})"))?;
    let nodes = &tree.nodes;
    let count = |n: &NodeOnWire<D>| n.data & 0x3fff_ffff;
    if nodes.is_empty() || count(&nodes[0][1]) == 0 {
        return Ok(());
    }
    let mut seen = vec![false; nodes.len()];
    let mut stack = vec![(0u32, 0u32)];
    while let Some((id, depth)) = stack.pop() {
        let Some(node) = nodes.get(id as usize) else {
            return Err(format!(
                "its broad phase names node {id} of {}",
                nodes.len()
            ));
        };
        if std::mem::replace(&mut seen[id as usize], true) {
            return Err(format!("its broad phase reaches node {id} twice (a loop)"));
        }
        for child in node {
            let leaves = count(child);
            if leaves == 0 {
                return Err(format!(
                    "its broad phase has an empty child under node {id}"
                ));
            }
            if leaves == 1 {
                continue;
            }
            let Some(inner) = nodes.get(child.children as usize) else {
                return Err(format!(
                    "its broad phase names node {} of {}",
                    child.children,
                    nodes.len()
                ));
            };
            if count(&inner[0]) as u64 + count(&inner[1]) as u64 != leaves as u64 {
                return Err(format!(
                    "its broad phase's leaf counts disagree at node {id}"
                ));
            }
            if depth + 1 > MAX_TREE_DEPTH {
                return Err(format!("its broad phase is deeper than {MAX_TREE_DEPTH}"));
            }
            stack.push((child.children, depth + 1));
        }
    }
    Ok(())
}
