//! How much of a light reaches a point: hard shadow rays (one ray, or four side by side as
//! a packet), soft shadows' samples over the light's extent after the rim probe, and the
//! casters a shadow ray meets under Unity's draw rules (objects that cast no shadow,
//! faces the material culls seen from the light, blended casters that let 1 − α through).

use super::*;

impl Integrator<'_> {
    /// Whether the hit triangle `prim` blocks a shadow ray (travelling towards the light)
    /// that meets its front (`front`) or back.
    #[inline(always)]
    fn casts(&self, prim: usize, front: bool) -> bool {
        self.sides[prim] & if front { CASTS_FRONT } else { CASTS_BACK } != 0
    }

    /// The share of a light's light that reaches the surface at `p` along unit `dir` from
    /// `dist` away (`dist` infinite: a directional light, the ray is unbounded): 0 when an
    /// opaque caster is in the way, the product of (1 − α) over the blended casters met
    /// otherwise. Cut-out holes are tested at full resolution: a shadow ray has no pixel
    /// footprint, and the full-size image gives the hole's true shape.
    pub(super) fn transmittance(
        &self,
        surf: &Surface,
        dir: Vec3,
        dist: f32,
        counts: &mut RayCounts,
    ) -> f32 {
        let ray = shadow_ray(surf.spawn(dir), surf.p, dir, dist);
        if !self.shadow_filter {
            return if self.accel.occluded(&ray) { 0.0 } else { 1.0 };
        }
        if !self.alpha {
            let blocked = self
                .accel
                .occluded_filtered(&ray, |hit, front| self.blocks(hit, front, counts));
            return if blocked { 0.0 } else { 1.0 };
        }
        self.transmittance_alpha(&ray, counts)
    }

    /// [`Integrator::transmittance`] of four shadow rays that leave one point towards one
    /// light (a soft shadow's samples), traced as one packet: the same four answers, bit
    /// for bit. `blocker` is an opaque caster that stopped an earlier sample of the point:
    /// a lane it stops is answered without a walk (so it counts no faces passed), and the
    /// packet's own opaque blockers replace it. Lanes not in `live` trace nothing and
    /// answer 0.
    pub(super) fn transmittance4(
        &self,
        rays: &[Ray; LANES],
        live: [bool; LANES],
        blocker: &mut Option<u32>,
        counts: &mut RayCounts,
    ) -> [f32; LANES] {
        let mut live = live;
        // A sample that the caster which blocked an earlier sample of this point blocks
        // too is dark whatever else lies on its way: one triangle test instead of a walk.
        if let Some(prim) = *blocker {
            for l in 0..LANES {
                if live[l] && self.blocked_by(prim, &rays[l]) {
                    live[l] = false;
                    counts.shadow_reuse += 1;
                }
            }
        }
        // A lane that is not live gets an empty interval: the packet never visits it.
        let rays = std::array::from_fn(|l| {
            if live[l] {
                rays[l]
            } else {
                Ray {
                    tmin: 1.0,
                    tmax: 0.0,
                    ..rays[l]
                }
            }
        });
        if self.alpha {
            let t = self.transmittance_alpha4(&rays, blocker, counts);
            return std::array::from_fn(|l| if live[l] { t[l] } else { 0.0 });
        }
        let mut casters = [None; LANES];
        let blocked = self.accel.occluded4_filtered(&rays, |l, hit, front| {
            let stops = !self.shadow_filter || self.blocks(hit, front, counts);
            if stops && self.opaque_caster(hit.prim, front) {
                casters[l] = Some(hit.prim);
            }
            stops
        });
        keep_last(blocker, casters);
        std::array::from_fn(|l| if live[l] && !blocked[l] { 1.0 } else { 0.0 })
    }

    /// Whether triangle `prim` stops every shadow ray that meets it from the side
    /// `front` says, wherever on it: it casts from that side and its material is opaque
    /// (a cut-out's holes and a blended surface's share depend on the point).
    #[inline(always)]
    fn opaque_caster(&self, prim: u32, front: bool) -> bool {
        let p = prim as usize;
        (!self.shadow_filter || self.casts(p, front))
            && (!self.alpha
                || self.surfacing[self.soup.tri_material[p] as usize].alpha == AlphaUse::Opaque)
    }

    /// Whether `ray` meets triangle `prim` within its interval, and `prim` stops it there
    /// ([`Integrator::opaque_caster`]): the watertight test the traversal runs on it.
    fn blocked_by(&self, prim: u32, ray: &Ray) -> bool {
        let Some(pre) = RayPre::new(ray.origin, ray.dir) else {
            return false;
        };
        let tri = self.soup.corners(prim as usize).map(|v| v.to_array());
        kdtree::triangle::intersect(&pre, &tri, ray.tmin, ray.tmax)
            .is_some_and(|h| self.opaque_caster(prim, h.front))
    }

    /// Whether a hit stops an opaque scene's shadow ray: a face that casts from the side
    /// met. The faces it passes are counted.
    #[inline(always)]
    fn blocks(&self, hit: &Hit, front: bool, counts: &mut RayCounts) -> bool {
        let casts = self.casts(hit.prim as usize, front);
        counts.shadow_pass_through += !casts as u64;
        casts
    }

    /// [`Integrator::transmittance`] through cut-out holes and blended casters, out of
    /// line so that scenes without them keep the old query's code.
    #[inline(never)]
    fn transmittance_alpha(&self, ray: &Ray, counts: &mut RayCounts) -> f32 {
        let mut share = 1.0f32;
        let mut seen = Seen::new();
        let stops = |hit: &Hit, front| self.stops(ray, hit, front, &mut share, &mut seen, counts);
        let blocked = if self.blend {
            self.accel.occluded_filtered_in_order(ray, stops)
        } else {
            self.accel.occluded_filtered(ray, stops)
        };
        if blocked {
            0.0
        } else {
            share
        }
    }

    /// [`Integrator::transmittance_alpha`] on four rays, one packet, each lane with its own
    /// share and blended points.
    #[inline(never)]
    fn transmittance_alpha4(
        &self,
        rays: &[Ray; LANES],
        blocker: &mut Option<u32>,
        counts: &mut RayCounts,
    ) -> [f32; LANES] {
        let mut share = [1.0f32; LANES];
        let mut seen: [Seen; LANES] = std::array::from_fn(|_| Seen::new());
        let mut casters = [None; LANES];
        let stops = |l: usize, hit: &Hit, front| {
            let stops = self.stops(&rays[l], hit, front, &mut share[l], &mut seen[l], counts);
            if stops && self.opaque_caster(hit.prim, front) {
                casters[l] = Some(hit.prim);
            }
            stops
        };
        let blocked = if self.blend {
            self.accel.occluded4_filtered_in_order(rays, stops)
        } else {
            self.accel.occluded4_filtered(rays, stops)
        };
        keep_last(blocker, casters);
        std::array::from_fn(|l| if blocked[l] { 0.0 } else { share[l] })
    }

    /// Whether a hit ends a shadow ray through cut-out and blended casters: an opaque
    /// caster, a cut-out's solid texel, or blended layers that leave no light (`share`, the
    /// light left, is attenuated by each blended object once per surface point, `seen`).
    #[inline(always)]
    fn stops(
        &self,
        ray: &Ray,
        hit: &Hit,
        front: bool,
        share: &mut f32,
        seen: &mut Seen,
        counts: &mut RayCounts,
    ) -> bool {
        let prim = hit.prim as usize;
        if !self.casts(prim, front) {
            counts.shadow_pass_through += 1;
            return false;
        }
        let s = &self.surfacing[self.soup.tri_material[prim] as usize];
        match s.alpha {
            AlphaUse::Opaque => true,
            AlphaUse::Cutout { cutoff } => {
                let hole = self.alpha_at(s, prim, hit, ray.dir, 0.0, counts) < cutoff;
                counts.shadow_pass_through += hole as u64;
                !hole
            }
            AlphaUse::Blend => {
                if !seen.first(self.soup.tri_object[prim], hit.t) {
                    return false;
                }
                counts.shadow_blend += 1;
                *share *= 1.0 - self.alpha_at(s, prim, hit, ray.dir, 0.0, counts);
                *share <= 0.0
            }
        }
    }

    /// Fraction of `soft_samples` stratified shadow rays that reach the light's extent: a
    /// disc of radius `shadow_radius` facing the point (point, spot) or a cone of angular
    /// diameter `shadow_radius` degrees around the light direction (directional).
    ///
    /// With the probe on, more samples than one packet and an extent at most 2° in angular
    /// radius ([`crate::soft::PROBE_MAX_DEGREES`]), four rays towards the rim of the extent
    /// go first: if all four let the same share of the light through (all reach it, all
    /// are stopped, or all pass the same blended layers), that is the answer and no sample
    /// is traced. Most points are wholly lit or wholly in shadow, and an edge that
    /// hides part of the extent hides part of its rim too unless it cuts off less than a
    /// tenth of the disc (the largest segment that misses four rim points a quarter turn
    /// apart) or a caster or a gap narrower than the disc slips between the probes: those
    /// are the probe's errors (`--soft-all` has none). Otherwise the samples are traced as
    /// without the probe, which does not count in the answer; the samples' random numbers
    /// are skipped when the probe decides, so every other point draws what it draws
    /// without the probe.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn soft_visibility(
        &self,
        surf: &Surface,
        light: &Light,
        inc: &Incident,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> f32 {
        let n = self.soft_samples;
        let mut spiral = DiscSpiral::new(n, rng.next_f32() * std::f32::consts::TAU);
        // A spawned origin depends on the side of the surface a ray leaves by, not on its
        // direction: two origins serve every sample.
        let above = surf.spawn(surf.ng);
        let below = surf.spawn(-surf.ng);
        let cone = SoftCone::new(light, surf.p, inc.dir, surf.ng, above, below);
        let mut visible = 0.0f32;
        // An opaque caster that stopped a probe is a good first guess for the samples.
        let mut blocker = None;
        if self.soft_probe && probe_fits(light, inc.dist) {
            let (dx, dy) = spiral.rim4();
            let (rays, traced) = cone.rays4(dx, dy);
            counts.soft_shadow += LANES as u64;
            let probe = self.transmittance4(&rays, traced, &mut blocker, counts);
            if probe.iter().all(|&v| v == probe[0]) {
                counts.soft_decided += 1;
                rng.advance(u64::from(n));
                return probe[0];
            }
        }
        // The samples leave one point towards one light, so four at a time share their walk
        // through the tree. Tracing draws nothing from `rng`: the samples are the same as
        // when each was traced before the next was drawn, and so is their sum.
        for first in (0..n).step_by(LANES) {
            let (mut dx, mut dy) = ([0.0; LANES], [0.0; LANES]);
            let mut drawn = [false; LANES];
            for l in 0..(n - first).min(LANES as u32) as usize {
                (dx[l], dy[l]) = spiral.next(rng.next_f32());
                counts.soft_shadow += 1;
                drawn[l] = true;
            }
            let (rays, traced) = cone.rays4(dx, dy);
            let live = std::array::from_fn(|l| drawn[l] && traced[l]);
            // Lanes that are not live answer 0, which leaves the sum as it was.
            for v in self.transmittance4(&rays, live, &mut blocker, counts) {
                visible += v;
            }
        }
        visible / n as f32
    }
}

/// The point's blocker after a packet: the opaque caster that stopped the packet's last
/// sample stopped by one, else the one before. By lane, not by the order the walk met them
/// in, so the blocker (and what later samples count) does not depend on how a leaf's
/// triangles are tested.
fn keep_last(blocker: &mut Option<u32>, casters: [Option<u32>; LANES]) {
    if let Some(&prim) = casters.iter().rev().flatten().next() {
        *blocker = Some(prim);
    }
}

/// The shadow ray from `origin` (spawned off the surface point `p` towards `dir`) along
/// unit `dir` towards a light `dist` away from `p` (`dist` infinite: a directional light,
/// the ray is unbounded), re-aimed and re-measured from the spawned origin and stopped
/// short of the light by a relative margin.
pub(crate) fn shadow_ray(origin: Vec3, p: Vec3, dir: Vec3, dist: f32) -> Ray {
    if dist.is_infinite() {
        return Ray {
            origin,
            dir,
            tmin: SPAWN_TMIN,
            tmax: f32::INFINITY,
        };
    }
    let to = p + dir * dist - origin;
    let d = to.length();
    Ray {
        origin,
        dir: to / d,
        tmin: SPAWN_TMIN,
        tmax: d * SHADOW_TMAX_FRACTION,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft::tests::sample;
    use crate::RenderOptions;
    use formats::{Alpha, Cull, LightKind, Material, Object, Shadows};

    fn material(cull: Cull, alpha: Alpha, opacity: f32) -> Material {
        Material {
            name: "m".into(),
            source: "test".into(),
            color: Vec3::splat(0.5),
            metallic: 0.0,
            smoothness: 0.0,
            smoothness_in_alpha: false,
            pbs: false,
            highlights: false,
            reflections: false,
            reflectivity: None,
            emission: Vec3::ZERO,
            cull,
            normal_map: None,
            emission_map: None,
            occlusion_map: None,
            metallic_map: None,
            unlit: false,
            albedo_map: None,
            opacity,
            alpha,
        }
    }

    fn light(kind: LightKind, position: Vec3, direction: Vec3, shadow_radius: f32) -> Light {
        Light {
            name: "l".into(),
            kind,
            position,
            direction,
            color: Vec3::ONE,
            intensity: 1.0,
            range: 50.0,
            attenuation: formats::Attenuation::BuiltIn,
            shadows: Shadows::Soft,
            shadow_radius,
            shadow_strength: 1.0,
            culling_mask: u32::MAX,
        }
    }

    /// The six faces of the box from `lo` spanning `d`, as (corner, u, v) quads whose
    /// fronts (u × v) face outwards.
    fn box_faces(lo: Vec3, d: Vec3) -> [(Vec3, Vec3, Vec3); 6] {
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

    /// A floor under a one-sided occluder, a closed one-sided box and, with `blend`, a
    /// half-transparent pane: casters that the shadow filter passes, a closed surface's
    /// culled entry face and blending.
    fn scene(blend: bool) -> (Soup, Accel) {
        let mut soup = Soup::empty();
        soup.materials = vec![
            material(Cull::None, Alpha::Opaque, 1.0),
            material(Cull::Back, Alpha::Opaque, 1.0),
            material(Cull::None, Alpha::Blend, 0.5),
        ];
        let quad = |soup: &mut Soup, o: Vec3, u: Vec3, v: Vec3, m: u32| {
            let obj = soup.objects.len() as u32;
            soup.objects.push(Object::new("q", "test"));
            let n = u.cross(v).normalize();
            let p = [o, o + u, o + u + v, o + v];
            for t in [[0, 1, 2], [0, 2, 3]] {
                soup.push_triangle(t.map(|i| p[i]), [n; 3], None);
                soup.tri_material.push(m);
                soup.tri_object.push(obj);
            }
        };
        quad(
            &mut soup,
            Vec3::new(-10.0, 0.0, -10.0),
            Vec3::Z * 20.0,
            Vec3::X * 20.0,
            0,
        );
        // Faces down: its back faces the lights, and Unity's shadow pass culls it.
        quad(
            &mut soup,
            Vec3::new(0.0, 2.0, -1.0),
            Vec3::X * 1.5,
            Vec3::Z * 2.0,
            1,
        );
        // A closed box, faces outwards, one-sided.
        for (o, u, v) in box_faces(Vec3::new(-3.0, 0.5, -3.0), Vec3::ONE) {
            quad(&mut soup, o, u, v, 1);
        }
        if blend {
            quad(
                &mut soup,
                Vec3::new(1.5, 1.0, 1.0),
                Vec3::Z * 1.5,
                Vec3::X * 1.5,
                2,
            );
        }
        soup.lights = vec![
            light(LightKind::Point, Vec3::new(3.0, 4.0, 0.5), -Vec3::Y, 0.7),
            light(
                LightKind::Directional,
                Vec3::ZERO,
                Vec3::new(-0.6, -0.8, 0.1),
                12.0,
            ),
        ];
        soup.seal();
        soup.validate().expect("valid test scene");
        let kd = kdtree::build(
            &soup.triangle_positions(),
            &formats::BuildParams::default(),
            soup.geometry_hash,
        );
        let accel = Accel::new(&soup, kd).expect("tree fits");
        (soup, accel)
    }

    /// The blocker a packet hands on is its highest stopped lane's, whatever order its
    /// lanes were stopped in; a packet with none keeps the one before.
    #[test]
    fn a_packet_hands_on_its_last_lane_blocker() {
        let mut blocker = Some(7);
        keep_last(&mut blocker, [None; LANES]);
        assert_eq!(blocker, Some(7));
        keep_last(&mut blocker, [Some(3), None, Some(9), None]);
        assert_eq!(blocker, Some(9));
        keep_last(&mut blocker, [Some(4), None, None, Some(2)]);
        assert_eq!(blocker, Some(2));
    }

    fn soft_options(soft_samples: u32, soft_probe: bool) -> RenderOptions {
        RenderOptions {
            soft_samples,
            soft_probe,
            ..RenderOptions::default()
        }
    }

    /// Point `i` of a 30 × 30 grid on the floor of [`scene`]; every other point is seen from
    /// below, so its rays leave by the other side.
    fn floor_point(i: usize) -> Surface {
        let p = Vec3::new(
            -6.0 + (i % 30) as f32 * 0.4,
            0.0,
            -6.0 + (i / 30) as f32 * 0.4,
        );
        Surface {
            p,
            err: Vec3::ZERO,
            margin: intersector_margin(&[p, p + Vec3::Z, p + Vec3::X]),
            ng: if i.is_multiple_of(2) {
                Vec3::Y
            } else {
                -Vec3::Y
            },
        }
    }

    /// The rim probe decides only points whose four probes agree, four rays each; every
    /// other point gets the samples' answer to the bit, and every point leaves the
    /// generator where the samples alone leave it. Where it decides, it misjudges few
    /// points, and those by little. Lights wider than 2° seen from the point are never
    /// probed.
    #[test]
    fn the_rim_probe_decides_agreeing_points_and_leaves_the_rest_exact() {
        for (blend, narrow) in [(false, true), (true, true), (false, false)] {
            let (mut soup, accel) = scene(blend);
            if narrow {
                // 0.1 m at 4 m or more (at most 1.4°), and a 3° cone (1.5° in radius).
                soup.lights[0].shadow_radius = 0.1;
                soup.lights[1].shadow_radius = 3.0;
            }
            let plan = Plan::derive(&soup, &RenderOptions::default());
            for n in [4, 9, 16, 64] {
                let probed = Integrator::new(&soup, &accel, &plan, &soft_options(n, true));
                let exact = Integrator::new(&soup, &accel, &plan, &soft_options(n, false));
                let asked = narrow && n > 4;
                let (mut points, mut decided, mut wrong, mut worst) = (0, 0, 0, 0.0f32);
                let mut penumbra = 0;
                for (k, light) in soup.lights.iter().enumerate() {
                    for i in 0..900 {
                        let surf = floor_point(i);
                        let Some(inc) = incident(light, surf.p) else {
                            continue;
                        };
                        let seed = (k * 1000 + i) as u64;
                        let (mut rng_a, mut a) = (Rng::new(seed), RayCounts::default());
                        let v = probed.soft_visibility(&surf, light, &inc, &mut rng_a, &mut a);
                        let (mut rng_b, mut b) = (Rng::new(seed), RayCounts::default());
                        let w = exact.soft_visibility(&surf, light, &inc, &mut rng_b, &mut b);
                        assert_eq!(rng_a.next_u32(), rng_b.next_u32(), "n {n}, point {i}");
                        points += 1;
                        penumbra += (w > 0.0 && w < 1.0) as u32;
                        if a.soft_decided == 1 {
                            assert!(asked && (0.0..=1.0).contains(&v), "n {n}: {v}");
                            assert_eq!(a.soft_shadow, 4);
                            decided += 1;
                            // A share summed over the samples may round differently.
                            if (v - w).abs() > 1e-6 {
                                wrong += 1;
                                worst = worst.max((v - w).abs());
                            }
                        } else {
                            assert_eq!(v.to_bits(), w.to_bits(), "n {n}, point {i}");
                            let probes = if asked { 4 } else { 0 };
                            assert_eq!(a.soft_shadow, b.soft_shadow + probes);
                        }
                    }
                }
                // Measured: 1,795 (solid) and 1,790 (blended) of 1,800 points decided at
                // every n > 4, 0–4 of them misjudged, by at most 0.0625.
                if asked {
                    assert!(decided * 2 > points, "n {n}: {decided} of {points}");
                    assert!(penumbra > 0, "n {n}: no penumbra to get wrong");
                    assert!(
                        wrong * 100 <= decided && worst <= 0.1,
                        "n {n}: {wrong} of {decided} misjudged, worst by {worst}"
                    );
                } else {
                    assert_eq!(decided, 0);
                }
            }
        }
    }

    /// Soft shadows traced four samples at a time, with the samples that the caster which
    /// blocked an earlier one blocks too taken as dark without a walk, give, point by
    /// point, the visibility and the generator state of tracing each sample alone with the
    /// hard shadows' query, bit for bit, for sample counts that fill four lanes, leave a
    /// tail or use one lane, through filtered, solid and blended casters, from either side
    /// of a surface.
    #[test]
    fn soft_samples_in_packets_and_reused_blockers_equal_samples_alone() {
        for blend in [false, true] {
            let (soup, accel) = scene(blend);
            let plan = Plan::derive(&soup, &RenderOptions::default());
            assert!(plan.shadow_casting.enabled && plan.alpha.enabled == blend);
            for n in [1, 3, 4, 9, 16] {
                let it = Integrator::new(&soup, &accel, &plan, &soft_options(n, false));
                let (mut dark, mut penumbra, mut lit) = (0, 0, 0);
                let (mut reused, mut blocked) = (0, 0);
                for (k, light) in soup.lights.iter().enumerate() {
                    for i in 0..900 {
                        let surf = floor_point(i);
                        let p = surf.p;
                        let Some(inc) = incident(light, p) else {
                            continue;
                        };
                        let seed = (k * 1000 + i) as u64;
                        let (mut rng_a, mut counts_a) = (Rng::new(seed), RayCounts::default());
                        let packed =
                            it.soft_visibility(&surf, light, &inc, &mut rng_a, &mut counts_a);

                        let (mut rng_b, mut counts_b) = (Rng::new(seed), RayCounts::default());
                        let mut spiral =
                            DiscSpiral::new(n, rng_b.next_f32() * std::f32::consts::TAU);
                        let cone = SoftCone::new(light, p, inc.dir, surf.ng, p, p);
                        let mut alone = 0.0f32;
                        for _ in 0..n {
                            let (dx, dy) = spiral.next(rng_b.next_f32());
                            counts_b.soft_shadow += 1;
                            if let Some((dir, dist)) = sample(&cone, dx, dy) {
                                let v = it.transmittance(&surf, dir, dist, &mut counts_b);
                                blocked += (v == 0.0) as u64;
                                alone += v;
                            }
                        }
                        let alone = alone / n as f32;
                        assert_eq!(
                            packed.to_bits(),
                            alone.to_bits(),
                            "n {n}, light {k}, point {p}"
                        );
                        // The samples a walk skipped met no faces to count.
                        assert_eq!(counts_a.soft_shadow, counts_b.soft_shadow);
                        reused += counts_a.shadow_reuse;
                        assert_eq!(rng_a.next_u32(), rng_b.next_u32());
                        match packed {
                            0.0 => dark += 1,
                            1.0 => lit += 1,
                            _ => penumbra += 1,
                        }
                    }
                }
                assert!(dark > 0 && lit > 0, "n {n}: {dark} dark, {lit} lit");
                if n > 1 {
                    assert!(penumbra > 20, "n {n}: {penumbra} penumbra points");
                }
                // Only a point's second packet on can reuse a blocker.
                if n > 4 {
                    assert!(
                        reused > 0 && reused < blocked,
                        "n {n}: {reused} of {blocked}"
                    );
                } else {
                    assert_eq!(reused, 0);
                }
            }
        }
    }
}
