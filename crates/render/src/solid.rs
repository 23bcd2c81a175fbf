//! Objects that are closed surfaces, and what that tells a shadow ray.
//!
//! With Unity's default culling the shadow pass draws only the faces that look at the
//! light, so a shadow ray (from the receiver towards the light) passes through the faces
//! that look back at the receiver. Behind a closed object, that is the face the ray
//! enters by, and the ray must go on to find the face it leaves by, which does cast:
//! almost every shadowed point pays for a walk through the object's inside. For a closed,
//! consistently wound mesh that walk can be skipped. Count crossings with sign: +1 where
//! the ray passes a face against its normal (entering), −1 along it (leaving). A ray
//! that starts and ends outside the mesh's box has net 0, so one that entered must, before
//! it ends, leave through a face it meets along that face's normal, which is a face the
//! shadow pass draws. The watertight triangle test finds every such crossing (no ray slips
//! between triangles sharing an edge), so the answer is the one the walk would give.

use ahash::RandomState;
use formats::{Alpha, CastShadows, Cull, Soup};
use glam::Vec3;
use kdtree::Ray;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering::Relaxed};
use std::sync::OnceLock;

/// The closed pieces of each object, worked out once enough shadow rays have passed into
/// that object to pay for it, and kept for the rest of the render.
pub struct Solids<'a> {
    soup: &'a Soup,
    /// Each object's triangles, a contiguous run of the soup (as the converter writes
    /// them); empty when the soup is not laid out so, and then no object is solid.
    runs: Vec<Range<usize>>,
    pieces: Vec<OnceLock<Pieces>>,
    /// Shadow rays that passed into each object so far.
    entered: Vec<AtomicU32>,
    /// Whether a thread has taken on finding each object's pieces.
    claimed: Vec<AtomicBool>,
}

/// One object's pieces: per triangle of its run, the number of its solid piece or
/// [`OPEN`], and each solid piece's box.
struct Pieces {
    local: Vec<u32>,
    boxes: Vec<[Vec3; 2]>,
}

const OPEN: u32 = u32::MAX;

impl<'a> Solids<'a> {
    /// Ready to answer for `soup`'s objects (one pass over its triangle-to-object map).
    pub fn new(soup: &'a Soup) -> Solids<'a> {
        let n = soup.objects.len();
        let mut runs = vec![0..0; n];
        let mut start = 0;
        for run in soup.tri_object.chunk_by(|a, b| a == b) {
            // An object met a second time is not one run.
            match runs.get_mut(run[0] as usize) {
                Some(r) if r.start == r.end => *r = start..start + run.len(),
                _ => return Self::none(soup),
            }
            start += run.len();
        }
        Solids {
            soup,
            runs,
            pieces: (0..n).map(|_| OnceLock::new()).collect(),
            entered: (0..n).map(|_| AtomicU32::new(0)).collect(),
            claimed: (0..n).map(|_| AtomicBool::new(false)).collect(),
        }
    }

    /// No object solid: for renders that never ask.
    pub fn none(soup: &'a Soup) -> Solids<'a> {
        Solids {
            soup,
            runs: Vec::new(),
            pieces: Vec::new(),
            entered: Vec::new(),
            claimed: Vec::new(),
        }
    }

    /// Whether `ray`, which met triangle `prim` on a face its shadow pass culls, is sure
    /// to meet a face of the same piece that casts before `ray.tmax`: the piece is solid
    /// (closed and casting as Unity's default shadow pass does) and the ray starts and ends
    /// outside its box.
    pub fn blocks(&self, prim: usize, ray: &Ray) -> bool {
        let Some(&o) = self.soup.tri_object.get(prim) else {
            return false;
        };
        let o = o as usize;
        let (Some(run), Some(cell)) = (self.runs.get(o), self.pieces.get(o)) else {
            return false;
        };
        // Finding the pieces costs about 500 instructions per triangle, a walk through an
        // inside about 2,000 (both measured on the baseline), so it waits until a quarter as
        // many rays as the object has triangles have entered: an object few shadow rays pass
        // into (most of a large scene's) never pays, and none pays much more than it saves.
        let pieces = match cell.get() {
            Some(p) => p,
            None => {
                // One thread finds them; the others walk on meanwhile rather than wait, and
                // only read the flag: a write per ray would bounce its cache line between
                // the threads.
                if self.claimed[o].load(Relaxed) {
                    return false;
                }
                let entered = self.entered[o].fetch_add(1, Relaxed) as usize + 1;
                if entered < run.len() / 4 || self.claimed[o].swap(true, Relaxed) {
                    return false;
                }
                cell.get_or_init(|| closed_pieces(self.soup, o, run.clone()))
            }
        };
        let Some(&p) = pieces.local.get(prim - run.start) else {
            return false;
        };
        let Some([lo, hi]) = pieces.boxes.get(p as usize) else {
            return false;
        };
        let inv = ray.dir.recip();
        let a = (*lo - ray.origin) * inv;
        let b = (*hi - ray.origin) * inv;
        let enter = a.min(b).max_element();
        let exit = a.max(b).min_element();
        enter > ray.tmin && exit < ray.tmax
    }
}

/// A vertex's bits, with −0 read as +0 so that equal coordinates compare equal.
fn key(p: Vec3) -> [u32; 3] {
    p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

/// Object `o`'s pieces (its triangles `run`). A piece is a set of its triangles joined
/// through edges (vertices compared bit for bit) used exactly twice, once in each
/// direction. It is solid when it is closed — no edge of it is used any other way — and
/// it casts as Unity's default shadow pass does: the object casts with its materials'
/// culling (`On` or `ShadowsOnly`), and every triangle's material is opaque and culls
/// back faces. Pieces, not whole objects, because a model is often several closed
/// parts and an open one (a body and its tail): the closed parts still qualify. A
/// triangle with a non-finite vertex (the tree leaves it out: a hole) opens its piece.
fn closed_pieces(soup: &Soup, o: usize, run: Range<usize>) -> Pieces {
    let casts_culled = matches!(
        soup.objects[o].cast_shadows,
        CastShadows::On | CastShadows::ShadowsOnly
    );
    if !casts_culled {
        return Pieces {
            local: Vec::new(),
            boxes: Vec::new(),
        };
    }
    // Welded by position, not by the soup's vertex numbers: a hard edge splits its
    // vertices, yet closes the piece.
    let list: Vec<[Vec3; 3]> = run.clone().map(|t| soup.corners(t)).collect();
    let n = list.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let mut open = vec![false; n];
    // Vertices numbered by their bits, then each edge (its two numbers, lower first) with
    // the triangles that use it: a hash lookup per corner and one per edge, a third of the
    // instructions of sorting the edges by their 24-byte keys.
    let mut vertex: HashMap<[u32; 3], u32, RandomState> =
        HashMap::with_capacity_and_hasher(n, RandomState::new());
    let mut edges: HashMap<u64, Uses, RandomState> =
        HashMap::with_capacity_and_hasher(n * 3 / 2, RandomState::new());
    for (i, tri) in list.iter().enumerate() {
        let m = &soup.materials[soup.tri_material[run.start + i] as usize];
        if !tri.iter().all(|p| p.is_finite()) || m.cull != Cull::Back || m.alpha != Alpha::Opaque {
            open[i] = true;
        }
        let mut id = |p: Vec3| {
            let next = vertex.len() as u32;
            *vertex.entry(key(p)).or_insert(next)
        };
        let v = [id(tri[0]), id(tri[1]), id(tri[2])];
        for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
            if a == b {
                open[i] = true;
                continue;
            }
            let forward = a < b;
            let k = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
            let u = edges.entry(k).or_insert(Uses {
                count: 0,
                first: 0,
                second: 0,
                forward,
            });
            let i = i as u32;
            match u.count {
                0 => u.first = i,
                1 => {
                    u.second = i;
                    if u.forward == forward {
                        open[i as usize] = true;
                        open[u.first as usize] = true;
                    }
                }
                _ => {
                    for t in [i, u.first, u.second] {
                        open[t as usize] = true;
                    }
                }
            }
            u.count += 1;
        }
    }
    for u in edges.values() {
        match u.count {
            1 => open[u.first as usize] = true,
            2 => union(&mut parent, u.first, u.second),
            _ => {}
        }
    }
    // A piece is open when any of its triangles is; each closed piece gets its box.
    let roots: Vec<u32> = (0..n as u32).map(|i| find(&mut parent, i)).collect();
    let mut piece_open = vec![false; n];
    let mut lo = vec![Vec3::splat(f32::INFINITY); n];
    let mut hi = vec![Vec3::splat(f32::NEG_INFINITY); n];
    for (i, &r) in roots.iter().enumerate() {
        let r = r as usize;
        piece_open[r] |= open[i];
        for p in list[i] {
            lo[r] = lo[r].min(p);
            hi[r] = hi[r].max(p);
        }
    }
    // Closed pieces numbered in order of their roots.
    let mut number = vec![OPEN; n];
    let mut boxes = Vec::new();
    for r in 0..n {
        if roots[r] == r as u32 && !piece_open[r] {
            number[r] = boxes.len() as u32;
            boxes.push(padded(lo[r], hi[r]));
        }
    }
    let local = roots.iter().map(|&r| number[r as usize]).collect();
    Pieces { local, boxes }
}

/// The triangles using one edge: the first two, and the direction of the first.
struct Uses {
    count: u32,
    first: u32,
    second: u32,
    forward: bool,
}

/// Union of the sets holding `a` and `b` (the smaller root joins the larger, so roots
/// are a deterministic choice).
fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        parent[hi as usize] = lo;
    }
}

/// The root of `i`'s set, halving the path on the way.
fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// A box grown by a relative margin, so that rounding in [`Solids::blocks`]'s box test
/// cannot call a ray outside that is inside.
fn padded(lo: Vec3, hi: Vec3) -> [Vec3; 2] {
    let pad = (hi - lo).max_element() * 1e-3 + lo.abs().max(hi.abs()).max_element() * 1e-5;
    [lo - Vec3::splat(pad), hi + Vec3::splat(pad)]
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use formats::{Material, Object};

    /// The six faces of the box from `lo` spanning `d`, as (corner, u, v) quads whose
    /// fronts (u × v) face outwards.
    pub(crate) fn box_faces(lo: Vec3, d: Vec3) -> [(Vec3, Vec3, Vec3); 6] {
        let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        [
            (lo, x, z),
            (lo + y, z, x),
            (lo, y, x),
            (lo + z, x, y),
            (lo, z, y),
            (lo + x, y, z),
        ]
    }

    /// One object: a closed unit cube at `lo` (outward faces, welded corners) and, when
    /// `with_quad`, a lone quad beside it.
    fn soup(with_quad: bool) -> Soup {
        let mut s = Soup::empty();
        s.objects.push(Object::new("thing", "test"));
        s.materials.push(Material {
            cull: Cull::Back,
            ..Material::unity_default()
        });
        let mut faces = box_faces(Vec3::new(2.0, 0.0, 0.0), Vec3::ONE).to_vec();
        if with_quad {
            faces.push((Vec3::new(-3.0, 0.0, 0.0), Vec3::X, Vec3::Z));
        }
        for (o, u, v) in faces {
            for t in [[o, o + u, o + u + v], [o, o + u + v, o + v]] {
                s.push_triangle(t, [Vec3::Y; 3], None);
                s.tri_material.push(0);
                s.tri_object.push(0);
            }
        }
        s
    }

    fn ray(origin: Vec3, dir: Vec3, tmax: f32) -> Ray {
        Ray::new(origin, dir, 0.0, tmax)
    }

    #[test]
    fn a_closed_cube_is_one_solid_piece_and_a_lone_quad_beside_it_is_open() {
        let s = soup(true);
        let p = closed_pieces(&s, 0, 0..s.triangles.len());
        assert_eq!(p.boxes.len(), 1);
        assert!(p.local[..12].iter().all(|&l| l == 0), "{:?}", p.local);
        assert!(p.local[12..].iter().all(|&l| l == OPEN), "{:?}", p.local);
        let [lo, hi] = p.boxes[0];
        assert!(
            lo.cmple(Vec3::new(2.0, 0.0, 0.0)).all()
                && lo.cmpgt(Vec3::new(1.99, -0.01, -0.01)).all(),
            "{lo}"
        );
        assert!(
            hi.cmpge(Vec3::new(3.0, 1.0, 1.0)).all() && hi.cmplt(Vec3::new(3.01, 1.01, 1.01)).all(),
            "{hi}"
        );
    }

    #[test]
    fn a_missing_or_flipped_face_or_a_two_sided_material_opens_the_cube() {
        let mut s = soup(false);
        s.triangles.pop();
        s.normals.pop();
        s.tri_material.pop();
        s.tri_object.pop();
        assert!(closed_pieces(&s, 0, 0..11).boxes.is_empty(), "a hole");
        let mut s = soup(false);
        s.triangles[5].swap(1, 2);
        assert!(
            closed_pieces(&s, 0, 0..12).boxes.is_empty(),
            "a flipped triangle"
        );
        let mut s = soup(false);
        s.materials[0].cull = Cull::None;
        assert!(closed_pieces(&s, 0, 0..12).boxes.is_empty(), "two-sided");
        let mut s = soup(false);
        s.objects[0].cast_shadows = CastShadows::TwoSided;
        assert!(
            closed_pieces(&s, 0, 0..12).boxes.is_empty(),
            "casting two-sided"
        );
    }

    #[test]
    fn blocks_only_rays_that_start_and_end_outside_the_piece() {
        let s = soup(false);
        let solids = Solids::new(&s);
        // Refused faces are asked about only once enough rays have entered.
        let through = ray(Vec3::new(2.5, -1.0, 0.5), Vec3::Y, 10.0);
        let asked: Vec<bool> = (0..7).map(|_| solids.blocks(0, &through)).collect();
        assert_eq!(asked, [false, false, true, true, true, true, true]);
        // From inside the box, or ending inside it: no answer.
        assert!(!solids.blocks(0, &ray(Vec3::new(2.5, 0.5, 0.5), Vec3::Y, 10.0)));
        assert!(!solids.blocks(0, &ray(Vec3::new(2.5, -1.0, 0.5), Vec3::Y, 1.5)));
        // A directional light's unbounded ray.
        assert!(solids.blocks(3, &ray(through.origin, Vec3::Y, f32::INFINITY)));
    }

    #[test]
    fn objects_not_laid_out_in_runs_are_never_solid() {
        let mut s = soup(false);
        s.objects.push(Object::new("other", "test"));
        s.tri_object[5] = 1;
        let solids = Solids::new(&s);
        assert!(solids.runs.is_empty());
        assert!((0..20).all(|_| !solids.blocks(0, &ray(Vec3::new(2.5, -1.0, 0.5), Vec3::Y, 10.0))));
    }
}
