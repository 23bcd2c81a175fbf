//! A hit's surface: its material's colour, alpha, metallic and smoothness, normal, emission
//! and occlusion, each map read once at the hit's UV and the footprint of the ray's cone
//! there, and the light it gives off whatever the lights do (emission, ambient).

use super::*;

impl Integrator<'_> {
    /// A surface hit's material, point and normals, and the light it gives off whatever
    /// the lights do (emission, ambient); fills `primary` (once). None where the surface
    /// is fully transparent there: it sends back nothing, α 0.
    #[inline(always)]
    pub(super) fn surface(
        &self,
        ray: &Ray,
        hit: &Hit,
        cone: RayCone,
        counts: &mut RayCounts,
        primary: &mut Option<&mut Primary>,
    ) -> Option<Lit> {
        let prim = hit.prim as usize;
        let mat_index = self.soup.tri_material[prim] as usize;
        let mat = &self.soup.materials[mat_index];
        // The colour a metal's highlight takes: colour times texel, before metallic.
        let mut base = mat.color;
        let mut texel_colour = None;
        let mut metallic = mat.metallic;
        let mut smoothness = mat.smoothness;
        let mut a = 1.0f32;
        let surfacing = self.surfacing.get(mat_index);
        // Every map of the surface is read at one UV and footprint, found at the first.
        let mut at = None;
        let mut lookup = |map: &(usize, Tiling)| {
            let fp = *at.get_or_insert_with(|| self.footprint(prim, hit, ray.dir, cone.at(hit.t)));
            self.sample(map, fp)
        };
        if let Some(s) = surfacing {
            let blend = s.alpha == AlphaUse::Blend;
            match &s.map {
                Some(map) if s.colour || blend => {
                    let texel = lookup(map);
                    if s.colour {
                        counts.texture_lookups += 1;
                        texel_colour = Some(texel.truncate());
                        base *= texel.truncate();
                        if mat.smoothness_in_alpha {
                            smoothness *= texel.w;
                        }
                    } else {
                        counts.alpha_lookups += 1;
                    }
                    if blend {
                        a = s.opacity * texel.w;
                    }
                }
                _ if blend => a = s.opacity,
                _ => {}
            }
            if a <= 0.0 {
                return None;
            }
            if let Some((i, tiling, scale)) = s.metallic {
                counts.metallic_lookups += 1;
                let texel = lookup(&(i, tiling));
                metallic = texel.x;
                if !mat.smoothness_in_alpha {
                    smoothness = scale * texel.w;
                }
            }
        }
        let mut albedo = mat.albedo_at(metallic);
        if let Some(texel) = texel_colour {
            albedo *= texel;
        }

        let tri = &self.soup.corners(prim);
        let (p, err) = hit_point(tri, hit.u, hit.v);

        // Geometric normal, turned to face where the ray came from.
        let mut ng = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize_or_zero();
        if ng.dot(ray.dir) > 0.0 {
            ng = -ng;
        }
        let surf = Surface {
            p,
            err,
            margin: intersector_margin(tri),
            ng,
        };
        let ns_tri = self.soup.corner_normals(prim);
        let b0 = 1.0 - hit.u - hit.v;
        let mut ns = (ns_tri[0] * b0 + ns_tri[1] * hit.u + ns_tri[2] * hit.v).normalize_or_zero();
        if ns == Vec3::ZERO || !ns.is_finite() {
            ns = ng;
        }
        // The side the ray sees is decided before the map bends the normal, which may
        // turn it past the ray at grazing angles.
        let back = ns.dot(ray.dir) > 0.0;
        if let Some((i, tiling, scale)) = surfacing.and_then(|s| s.normal) {
            counts.normal_lookups += 1;
            let texel = lookup(&(i, tiling));
            let tangent = self
                .tangents
                .as_ref()
                .and_then(|t| t.at(prim, hit.u, hit.v));
            let tangent = tangent
                .or_else(|| normal_map::triangle_tangent(ns, *tri, self.soup.corner_uvs(prim)));
            if let Some(tangent) = tangent {
                ns = normal_map::bend(ns, tangent, texel, scale);
            }
        }
        if back {
            ns = -ns;
        }

        let obj = &self.soup.objects[self.soup.tri_object[prim] as usize];
        if let Some(pr) = primary.take() {
            *pr = Primary {
                depth: hit.t,
                normal: ns,
                albedo,
                object: self.soup.tri_object[prim] as f32,
            };
        }

        let mut l = Vec3::ZERO;
        if self.emission {
            match surfacing.and_then(|s| s.emission) {
                Some(map) => {
                    counts.emission_lookups += 1;
                    l += mat.emission * lookup(&map).truncate();
                }
                None => l += mat.emission,
            }
        }
        // An unlit surface shows its colour as it is; a black albedo cannot show any light:
        // neither asks a light or traces a shadow ray.
        if mat.unlit {
            l += albedo;
        }
        let pbs = mat.pbs && !mat.unlit;
        // Without lights only the diffuse share matters (to the ambient light).
        let lights = !self.lights.is_empty();
        let gloss = Some(self.brdf)
            .filter(|_| pbs && mat.highlights && lights)
            .map(|brdf| brdf.gloss(base, metallic, smoothness, ns, -ray.dir))
            .filter(Gloss::any);
        let lit = !mat.unlit && (albedo.max_element() > 0.0 || gloss.is_some());
        // What the diffuse term lights (the AOV keeps the albedo).
        let diffuse_colour = if pbs {
            albedo * self.brdf.diffuse_share()
        } else {
            albedo
        };
        let diffuse = if pbs && lights {
            self.brdf.diffuse(smoothness, ns, -ray.dir)
        } else {
            Diffuse::LAMBERT
        };
        let mut reflectance = mat.reflectance_at(metallic, smoothness);
        let probe = self.probe.as_deref().filter(|_| pbs);
        // The share of ambient light and reflection the occlusion map leaves (1 without
        // one: a product with 1 leaves every other pixel's bits as they were).
        let occlusion = match surfacing.and_then(|s| s.occlusion) {
            Some((i, tiling, strength))
                if (lit && self.ambient)
                    || probe.is_some()
                    || (self.max_depth > 0 && reflectance.max_element() > 0.0) =>
            {
                counts.occlusion_lookups += 1;
                1.0 + (lookup(&(i, tiling)).y - 1.0) * strength
            }
            _ => 1.0,
        };
        reflectance *= occlusion;
        if lit && self.ambient {
            let ambient = match &self.sky_ambient {
                Some(sky) => sky.at(ns),
                None => environment::ambient(&self.soup.environment, ns),
            };
            l += ambient * diffuse_colour * occlusion;
        }
        if let Some(probe) = probe {
            // Unity's reflection of the probe, less what the traced mirror ray brings.
            let view = -ray.dir;
            let nv = ns.dot(view);
            let w = self.brdf.environment(base, metallic, smoothness, nv) * occlusion;
            let w = (w - reflectance).max(Vec3::ZERO);
            if w.max_element() > 0.0 {
                let seen = if mat.reflections {
                    counts.probe_lookups += 1;
                    probe.at(ns * (2.0 * nv) - view, smoothness)
                } else {
                    probe.mean
                };
                l += w * seen;
            }
        }
        Some(Lit {
            fade: self.shadow_fade.map_or(0.0, |f| f.at(surf.p)),
            l,
            a,
            albedo: diffuse_colour,
            diffuse,
            view: -ray.dir,
            gloss,
            lit,
            surf,
            ns,
            layer: obj.layer,
            receives: obj.receive_shadows,
            reflectance,
        })
    }

    /// The interpolated UV of triangle `prim` at barycentrics (u, v): corner 0 weighs
    /// 1 − u − v, corner 1 u, corner 2 v, as for the normals.
    fn uv_at(&self, prim: usize, u: f32, v: f32) -> Vec2 {
        let t = self.soup.corner_uvs(prim);
        t[0] * (1.0 - u - v) + t[1] * u + t[2] * v
    }

    /// The map's RGBA at a hit of `prim` along `dir`, where the ray's cone is `width` wide
    /// (0: the full-size image, for shadow rays, which have no pixel footprint).
    fn texel(&self, map: &(usize, Tiling), prim: usize, hit: &Hit, dir: Vec3, width: f32) -> Vec4 {
        self.sample(map, self.footprint(prim, hit, dir, width))
    }

    /// The hit's UV and the footprint of a ray cone `width` wide there, in UV units: what
    /// every map of the surface is read at.
    fn footprint(&self, prim: usize, hit: &Hit, dir: Vec3, width: f32) -> (Vec2, f32) {
        let uv = self.uv_at(prim, hit.u, hit.v);
        let w = if self.filter == TextureFilter::Cone && width > 0.0 {
            cone_footprint(
                width,
                dir,
                self.soup.corners(prim),
                self.soup.corner_uvs(prim),
            )
        } else {
            0.0
        };
        (uv, w)
    }

    /// The map's RGBA at a [`Integrator::footprint`].
    fn sample(&self, map: &(usize, Tiling), (uv, w): (Vec2, f32)) -> Vec4 {
        self.samplers[map.0]
            .as_ref()
            .expect("the plan reads every texture a lookup can reach")
            .lookup(self.filter, &map.1, uv, w)
    }

    /// α of a cut-out or blended surface at a hit (its opacity without a map).
    pub(super) fn alpha_at(
        &self,
        s: &Surfacing,
        prim: usize,
        hit: &Hit,
        dir: Vec3,
        width: f32,
        counts: &mut RayCounts,
    ) -> f32 {
        match &s.map {
            Some(map) => {
                counts.alpha_lookups += 1;
                s.opacity * self.texel(map, prim, hit, dir, width).w
            }
            None => s.opacity,
        }
    }
}
