//! `TESELA_light_linking` (node): Blender's light and shadow linking, resolved into the sets
//! of [`LightLinks`].
//!
//! An emitter names a link collection for its receivers and one for its blockers; objects
//! carry their state (include or exclude) in link collections. Emitter `E` with collection
//! `c` reaches object `O` when `O` is included in `c`, or when `O` has no state in `c` and no
//! object is included in `c` (a collection of exclusions only reaches everything else).
//! Objects with the same states in every collection of a kind form one set, so an emitter's
//! reach is a bit mask over sets, as Cycles keeps it.

use super::{Loader, extension, member};
use crate::scene::LightLinks;
use serde_json::Value;
use std::collections::HashMap;

/// The sets a bit mask can tell apart.
const MAX_SETS: usize = 64;

/// One node's extension: its receiver and blocker collections as an emitter, and its states
/// in link collections (`true`: included).
#[derive(Default)]
struct NodeLinks {
    receivers: Option<u64>,
    blockers: Option<u64>,
    states: Vec<(u64, bool)>,
}

/// One kind of linking (light or shadow) over every node: each node's set, and each emitter
/// node's mask of the sets it reaches.
struct Resolved {
    set_of: HashMap<usize, u8>,
    reach_of: HashMap<usize, u64>,
}

/// Resolves one kind: `collection_of` gives an emitter node's collection of that kind.
fn resolve(
    nodes: &[(usize, NodeLinks)],
    collection_of: impl Fn(&NodeLinks) -> Option<u64>,
    kind: &str,
    warnings: &mut Vec<String>,
) -> Resolved {
    // Collections emitters use, in node order → bit.
    let mut bit_of: HashMap<u64, u32> = HashMap::new();
    for (ni, l) in nodes {
        if let Some(c) = collection_of(l)
            && !bit_of.contains_key(&c)
        {
            if bit_of.len() == 64 {
                warnings.push(format!(
                    "node {ni}: TESELA_light_linking: more than 64 {kind} collections; this one is ignored"
                ));
                continue;
            }
            bit_of.insert(c, bit_of.len() as u32);
        }
    }
    // Each node's (included, excluded) masks; the last state given for a collection counts.
    let mut any_included = 0u64;
    let mut signatures = Vec::new();
    for (ni, l) in nodes {
        let (mut inc, mut exc) = (0u64, 0u64);
        for &(c, included) in &l.states {
            let Some(&b) = bit_of.get(&c) else { continue };
            let m = 1u64 << b;
            if included {
                (inc, exc) = (inc | m, exc & !m);
            } else {
                (inc, exc) = (inc & !m, exc | m);
            }
        }
        any_included |= inc;
        signatures.push((*ni, inc, exc));
    }
    // Set 0 holds the objects without states; each other signature gets the next set.
    let mut sets: Vec<(u64, u64)> = vec![(0, 0)];
    let mut set_of = HashMap::new();
    for &(ni, inc, exc) in &signatures {
        let s = match sets.iter().position(|&x| x == (inc, exc)) {
            Some(s) => s,
            None if sets.len() < MAX_SETS => {
                sets.push((inc, exc));
                sets.len() - 1
            }
            None => {
                warnings.push(format!(
                    "node {ni}: TESELA_light_linking: more than {MAX_SETS} different {kind} link states; this object is treated as unlinked"
                ));
                0
            }
        };
        if s != 0 {
            set_of.insert(ni, s as u8);
        }
    }
    let mut reach_of = HashMap::new();
    for (ni, l) in nodes {
        let Some(&b) = collection_of(l).and_then(|c| bit_of.get(&c)) else {
            continue;
        };
        let m = 1u64 << b;
        let mut reach = 0u64;
        for (s, &(inc, exc)) in sets.iter().enumerate() {
            let reached = inc & m != 0 || (exc & m == 0 && any_included & m == 0);
            if reached {
                reach |= 1u64 << s;
            }
        }
        // Sets that do not exist stay reached, as with no linking at all.
        if sets.len() < 64 && any_included & m == 0 {
            reach |= !0u64 << sets.len();
        }
        reach_of.insert(*ni, reach);
    }
    Resolved { set_of, reach_of }
}

/// The node's extension read, with what is malformed reported.
fn read(ni: usize, ext: &Value, warnings: &mut Vec<String>) -> NodeLinks {
    let mut bad = |what: &str| {
        warnings.push(format!(
            "node {ni}: TESELA_light_linking: `{what}` is malformed and ignored"
        ))
    };
    let mut collection = |key: &str| match member(ext, key) {
        None => None,
        Some(v) => v.as_u64().or_else(|| {
            bad(key);
            None
        }),
    };
    let receivers = collection("receivers");
    let blockers = collection("blockers");
    let mut states = Vec::new();
    if let Some(v) = member(ext, "links") {
        for item in v.as_array().into_iter().flatten() {
            let pair = item.as_array().filter(|p| p.len() == 2);
            let c = pair.and_then(|p| p[0].as_u64());
            let state = pair.and_then(|p| p[1].as_str());
            match (c, state) {
                (Some(c), Some("INCLUDE")) => states.push((c, true)),
                (Some(c), Some("EXCLUDE")) => states.push((c, false)),
                _ => bad("links"),
            }
        }
        if !v.is_array() {
            bad("links");
        }
    }
    NodeLinks {
        receivers,
        blockers,
        states,
    }
}

impl Loader<'_> {
    /// Reads every node's `TESELA_light_linking` into [`Loader::links`] (before the nodes are
    /// walked: a node's sets depend on every other node's states).
    pub(crate) fn light_linking(&mut self) {
        let Some(nodes) = member(self.raw, "nodes").and_then(Value::as_array) else {
            return;
        };
        let mut warnings = Vec::new();
        let linked: Vec<(usize, NodeLinks)> = (nodes.iter().enumerate())
            .filter_map(|(ni, n)| {
                extension(n, "TESELA_light_linking").map(|e| (ni, read(ni, e, &mut warnings)))
            })
            .collect();
        if linked.is_empty() {
            return;
        }
        let light = resolve(&linked, |l| l.receivers, "receiver", &mut warnings);
        let shadow = resolve(&linked, |l| l.blockers, "blocker", &mut warnings);
        for (ni, _) in &linked {
            let links = LightLinks {
                receiver_set: light.set_of.get(ni).copied().unwrap_or(0),
                blocker_set: shadow.set_of.get(ni).copied().unwrap_or(0),
                lights: light.reach_of.get(ni).copied().unwrap_or(LightLinks::ALL),
                shadowed_by: shadow.reach_of.get(ni).copied().unwrap_or(LightLinks::ALL),
            };
            if links != LightLinks::default() {
                self.links.insert(*ni, links);
            }
        }
        for w in warnings {
            self.warn_once(w);
        }
    }

    /// The linking of node `ni`.
    pub(crate) fn links_of(&self, ni: usize) -> LightLinks {
        self.links.get(&ni).copied().unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(receivers: Option<u64>, states: &[(u64, bool)]) -> NodeLinks {
        NodeLinks {
            receivers,
            blockers: None,
            states: states.to_vec(),
        }
    }

    /// Whether the emitter node `e` lights object node `o`.
    fn lit(r: &Resolved, e: usize, o: usize) -> bool {
        let set = r.set_of.get(&o).copied().unwrap_or(0);
        r.reach_of.get(&e).copied().unwrap_or(LightLinks::ALL) >> set & 1 != 0
    }

    #[test]
    fn inclusions_light_only_those_exclusions_all_but_those() {
        // Nodes: 0 emitter of collection 7 (includes 2), 1 emitter of collection 8 (excludes
        // 2 and 3), 2 and 3 members, 4 an object in no collection.
        let nodes = vec![
            (0, node(Some(7), &[])),
            (1, node(Some(8), &[])),
            (2, node(None, &[(7, true), (8, false)])),
            (3, node(None, &[(8, true), (8, false)])),
            (4, node(None, &[])),
        ];
        let mut w = Vec::new();
        let r = resolve(&nodes, |l| l.receivers, "receiver", &mut w);
        assert!(w.is_empty());
        assert!(lit(&r, 0, 2) && !lit(&r, 0, 3) && !lit(&r, 0, 4));
        // The last state given counts: node 3 is excluded from collection 8.
        assert!(!lit(&r, 1, 2) && !lit(&r, 1, 3) && lit(&r, 1, 4));
        // An emitter of an empty or unused collection reaches everything.
        let r = resolve(&nodes[..1], |l| l.receivers, "receiver", &mut w);
        assert_eq!(r.reach_of[&0], LightLinks::ALL);
    }
}
