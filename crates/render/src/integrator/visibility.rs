//! What camera and mirror rays see under Unity's draw rules: the closest hit that is not a
//! face its material culls, a shadows-only object or a cut-out hole, each refused inside one
//! traversal rather than by tracing again.

use super::*;

impl Integrator<'_> {
    /// The closest hit camera and reflection rays see, passing through culled faces,
    /// shadows-only objects and cut-out holes inside one traversal (each pass-through
    /// counted). Holes are tested at the cone's footprint, the lookup that shades the
    /// surface, so a cut-out's edge and its colour come from the same mip level, as in
    /// Unity's `clip()` on the sampled alpha.
    pub(super) fn first_visible(
        &self,
        ray: &Ray,
        cone: RayCone,
        counts: &mut RayCounts,
    ) -> Option<Hit> {
        // Each combination gets its own closure, so a scene without cut-outs runs the
        // culling test alone, as it did before alpha existed.
        match (self.culling, self.alpha) {
            (false, false) => self.accel.intersect(ray),
            (true, false) => {
                // Most rays meet a drawn face first, and most culled faces a filter would
                // be asked about lie behind that face anyway: so a query that takes every
                // hit (keeping the side of the one it ends with), and the filtered one only
                // from a refused hit on (same answer, ties included).
                let mut front = true;
                let first = self.accel.intersect_filtered(ray, |_, f| {
                    front = f;
                    true
                })?;
                self.unless_culled(ray, first, front, counts)
            }
            (_, true) => self.first_visible_alpha(ray, cone, counts),
        }
    }

    /// [`Integrator::first_visible`] for four rays that travel side by side, as packet
    /// queries: lane by lane the same answers, and the same filters asked in the same
    /// order, so the same counts.
    pub(super) fn first_visible4(
        &self,
        rays: &[Ray; LANES],
        cones: &[RayCone; LANES],
        counts: &mut RayCounts,
    ) -> [Option<Hit>; LANES] {
        match (self.culling, self.alpha) {
            (false, false) => self.accel.intersect4(rays),
            (true, false) => {
                let mut front = [true; LANES];
                let first = self.accel.intersect4_filtered(rays, |l, _, f| {
                    front[l] = f;
                    true
                });
                self.unless_culled4(rays, first, front, counts)
            }
            (_, true) => self.first_visible_alpha4(rays, cones, counts),
        }
    }

    /// [`Integrator::unless_culled`] on four lanes: the lanes whose first hit is culled
    /// walk on from it together, as one packet.
    #[inline(always)]
    fn unless_culled4(
        &self,
        rays: &[Ray; LANES],
        first: [Option<Hit>; LANES],
        front: [bool; LANES],
        counts: &mut RayCounts,
    ) -> [Option<Hit>; LANES] {
        let culled = std::array::from_fn(|l| {
            first[l].is_some_and(|h| self.culled(h.prim as usize, front[l]))
        });
        if culled == [false; LANES] {
            return first;
        }
        let rest = std::array::from_fn(|l| match first[l] {
            Some(hit) if culled[l] => {
                counts.pass_through += 1;
                Ray {
                    tmin: hit.t,
                    ..rays[l]
                }
            }
            _ => no_ray(),
        });
        let behind = self.accel.intersect4_filtered(&rest, |l, hit, front| {
            if first[l].is_some_and(|f| f.prim == hit.prim) {
                return false;
            }
            let through = self.culled(hit.prim as usize, front);
            counts.pass_through += through as u64;
            !through
        });
        std::array::from_fn(|l| if culled[l] { behind[l] } else { first[l] })
    }

    /// `first`, the ray's closest hit met on its front (`front`) or back, when its face is
    /// drawn; else the closest drawn face behind it (each pass-through counted).
    #[inline(always)]
    fn unless_culled(
        &self,
        ray: &Ray,
        first: Hit,
        front: bool,
        counts: &mut RayCounts,
    ) -> Option<Hit> {
        if !self.culled(first.prim as usize, front) {
            return Some(first);
        }
        counts.pass_through += 1;
        let rest = Ray {
            tmin: first.t,
            ..*ray
        };
        self.accel.intersect_filtered(&rest, |hit, front| {
            if hit.prim == first.prim {
                return false;
            }
            let through = self.culled(hit.prim as usize, front);
            counts.pass_through += through as u64;
            !through
        })
    }

    /// [`Integrator::first_visible`] with cut-out holes, out of line so that scenes
    /// without them keep the old query's code.
    #[inline(never)]
    fn first_visible_alpha(&self, ray: &Ray, cone: RayCone, counts: &mut RayCounts) -> Option<Hit> {
        self.accel
            .intersect_filtered(ray, |hit, front| self.shows(ray, cone, hit, front, counts))
    }

    /// [`Integrator::first_visible_alpha`] on four rays, one packet.
    #[inline(never)]
    fn first_visible_alpha4(
        &self,
        rays: &[Ray; LANES],
        cones: &[RayCone; LANES],
        counts: &mut RayCounts,
    ) -> [Option<Hit>; LANES] {
        self.accel.intersect4_filtered(rays, |l, hit, front| {
            self.shows(&rays[l], cones[l], hit, front, counts)
        })
    }

    /// Whether a camera or reflection ray stops at `hit` in a scene with cut-outs: not a
    /// culled face (met on its front, `front`, or back), nor a hole of a cut-out at the
    /// ray cone's footprint. Pass-throughs are counted.
    #[inline(always)]
    fn shows(
        &self,
        ray: &Ray,
        cone: RayCone,
        hit: &Hit,
        front: bool,
        counts: &mut RayCounts,
    ) -> bool {
        let prim = hit.prim as usize;
        let s = &self.surfacing[self.soup.tri_material[prim] as usize];
        let through = (self.culling && self.culled(prim, front))
            || matches!(s.alpha, AlphaUse::Cutout { cutoff }
                if self.alpha_at(s, prim, hit, ray.dir, cone.at(hit.t), counts) < cutoff);
        counts.pass_through += through as u64;
        !through
    }

    /// Whether camera and reflection rays pass through triangle `prim`, met on its front
    /// (`front`) or back: a shadows-only object, or a face its material culls.
    #[inline(always)]
    fn culled(&self, prim: usize, front: bool) -> bool {
        self.sides[prim] & if front { DRAWN_FRONT } else { DRAWN_BACK } == 0
    }
}
