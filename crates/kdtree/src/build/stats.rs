//! Statistics of a built tree, measured by walking it with each node's cell.

use crate::aabb::Aabb;
use formats::{BuildParams, KdFile, TreeStats};

/// Count nodes, leaves, references and depth, and the SAH cost of the tree: the expected
/// cost of a ray through the root cell, in units of one triangle test.
pub fn measure(kd: &KdFile, triangles: u64, params: &BuildParams) -> TreeStats {
    let mut s = TreeStats {
        triangles,
        nodes: kd.nodes.len() as u64,
        ..Default::default()
    };
    let root = Aabb {
        lo: kd.bounds[0].to_array(),
        hi: kd.bounds[1].to_array(),
    };
    let root_area = root.area();
    let super::Costs { kt, ki, .. } = super::Costs::of(params);
    let mut cost = 0.0;
    let mut stack = vec![(0usize, root, 0u32)];
    while let Some((i, cell, depth)) = stack.pop() {
        let node = kd.nodes[i];
        s.max_depth = s.max_depth.max(depth);
        let p = if root_area > 0.0 {
            cell.area() / root_area
        } else {
            1.0
        };
        if node.is_leaf() {
            s.leaves += 1;
            let c = node.count();
            if c == 0 {
                s.empty_leaves += 1;
            }
            s.references += c as u64;
            s.max_leaf_triangles = s.max_leaf_triangles.max(c);
            cost += ki * p * c as f64;
        } else {
            cost += kt * p;
            let (b, a) = cell.split(node.axis(), node.split());
            stack.push((node.above_child() as usize, a, depth + 1));
            stack.push((i + 1, b, depth + 1));
        }
    }
    s.sah_cost = cost / ki;
    s
}
