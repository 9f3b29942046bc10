//! Every builder's tree records, in each interior node, the primitive references under it (the
//! sum of its children's): the conversion to wide nodes trusts those counts instead of counting
//! the tree itself, so a wrong one would misplace leaves.

use englobe::accel::SeedPairing;
use englobe::accel::bvh::build::{collapse::collapse_leaves, treelet::restructure};
use englobe::accel::bvh::{BinnedSah, BuildKind, BuildTree, Ploc, SweepSah};
use englobe::{Aabb, Vec3};

/// Whether every node reachable from the root records the primitives under it.
fn counts_agree(tree: &BuildTree) -> bool {
    let mut under = vec![None; tree.nodes.len()];
    let mut stack = vec![(tree.root, false)];
    while let Some((id, children_done)) = stack.pop() {
        let node = &tree.nodes[id as usize];
        match node.kind {
            BuildKind::Leaf { count, .. } => under[id as usize] = Some(count),
            BuildKind::Interior { children: [a, b], .. } if children_done => {
                under[id as usize] = under[a as usize].zip(under[b as usize]).map(|(x, y)| x + y);
            }
            BuildKind::Interior { children: [a, b], .. } => stack.extend([(id, true), (a, false), (b, false)]),
        }
    }
    under[tree.root as usize] == Some(tree.prims.len() as u32)
        && tree.nodes.iter().zip(&under).all(|(n, u)| u.is_none_or(|u| u == n.prims_under()))
}

#[test]
fn every_builder_records_the_primitives_under_each_node() {
    // Boxes in a pseudo-random cloud, enough for the parallel builds.
    let boxes: Vec<Aabb> = (0..40_000u32)
        .map(|i| {
            let h = |k: u32| (i.wrapping_mul(2_654_435_761).wrapping_add(k.wrapping_mul(40_503)) % 10_007) as f32;
            let p = Vec3::new(h(1), h(2), h(3)) * 0.01;
            Aabb::new(p, p + Vec3::splat(0.05 + h(4) * 1e-5))
        })
        .collect();
    let trees = [
        BinnedSah::default().build_tree(&boxes),
        SweepSah::default().build_tree(&boxes[..3_000]),
        Ploc::default().build_tree(&boxes),
        SeedPairing::build_tree(&boxes[..3_000]),
    ];
    for tree in trees {
        assert!(counts_agree(&tree));
        assert!(counts_agree(&collapse_leaves(&tree, 4)));
        let mut restructured = tree.clone();
        restructure(&mut restructured, 4, 1);
        assert!(counts_agree(&restructured));
    }
    // A count that is not its children's sum is caught.
    let mut tree = BinnedSah::default().build_tree(&boxes[..100]);
    if let BuildKind::Interior { count, .. } = &mut tree.nodes[tree.root as usize].kind {
        *count += 1;
    }
    assert!(!counts_agree(&tree));
}
