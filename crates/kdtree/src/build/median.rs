//! A spatial-median k-d tree (split the cell's longest axis in the middle): the baseline
//! that shows what the SAH buys. Same node format, so the same traversal runs on it.

use crate::aabb::Aabb;
use formats::{BuildParams, KdFile, KdNode};
use glam::Vec3;

/// Build a median-split tree with leaves of at most 8 triangles (or the depth bound).
pub fn build_median(
    triangles: &[[Vec3; 3]],
    params: &BuildParams,
    geometry_hash: formats::Digest,
) -> KdFile {
    let start = std::time::Instant::now();
    let boxes: Vec<Aabb> = triangles.iter().map(Aabb::of_triangle).collect();
    let ids: Vec<u32> = (0..triangles.len() as u32)
        .filter(|&i| triangles[i as usize].iter().all(|v| v.is_finite()))
        .collect();
    let cell = ids
        .iter()
        .fold(Aabb::EMPTY, |a, &i| a.union(&boxes[i as usize]));
    let max_depth = super::depth_bound(params, ids.len());
    let mut tree = super::Subtree::default();
    rec(
        &boxes,
        ids,
        cell,
        0,
        max_depth,
        &mut tree.nodes,
        &mut tree.leaf_tris,
    );
    super::finish(triangles.len(), params, geometry_hash, cell, tree, start)
}

fn rec(
    boxes: &[Aabb],
    ids: Vec<u32>,
    cell: Aabb,
    depth: u32,
    max_depth: u32,
    nodes: &mut Vec<KdNode>,
    leaf_tris: &mut Vec<u32>,
) {
    let axis = (0..3)
        .max_by(|&a, &b| (cell.hi[a] - cell.lo[a]).total_cmp(&(cell.hi[b] - cell.lo[b])))
        .unwrap_or(0);
    let mid = 0.5 * (cell.lo[axis] + cell.hi[axis]);
    if ids.len() <= 8 || depth >= max_depth || !(mid > cell.lo[axis] && mid < cell.hi[axis]) {
        nodes.push(KdNode::leaf(ids.len() as u32, leaf_tris.len() as u32));
        leaf_tris.extend_from_slice(&ids);
        return;
    }
    // Box overlap (not clipping): a triangle touching the plane from one side stays there.
    let below: Vec<u32> = ids
        .iter()
        .copied()
        .filter(|&i| boxes[i as usize].lo[axis] < mid || boxes[i as usize].hi[axis] <= mid)
        .collect();
    let above: Vec<u32> = ids
        .iter()
        .copied()
        .filter(|&i| boxes[i as usize].hi[axis] > mid || boxes[i as usize].lo[axis] >= mid)
        .collect();
    let (cb, ca) = cell.split(axis, mid);
    let at = nodes.len();
    nodes.push(KdNode::leaf(0, 0));
    rec(boxes, below, cb, depth + 1, max_depth, nodes, leaf_tris);
    let above_at = nodes.len() as u32;
    rec(boxes, above, ca, depth + 1, max_depth, nodes, leaf_tris);
    nodes[at] = KdNode::interior(axis as u32, mid, above_at);
}
