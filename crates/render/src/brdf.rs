//! How Unity's physically based shaders (Standard, URP Lit) light a surface with a punctual
//! light, in each pipeline's own formula, so that a surface has the brightness and a
//! highlight the size it has in the editor: the diffuse term's share of the albedo and, in
//! the built-in pipeline, its Disney shape; the specular highlight.
//!
//! Both pipelines fold π into the light's intensity (albedo · cosine, no 1/π), and both
//! work in the metallic workflow: a surface reflects f0 = lerp(dielectric, colour,
//! metallic) at normal incidence and lights (1 − dielectric)·(1 − metallic) of its colour
//! as diffuse, and the roughness that shapes the GGX lobe is (1 − smoothness)².

use formats::{Attenuation, ColorSpace, Material};
use glam::Vec3;

/// Unity's reflectance of a dielectric at normal incidence (`unity_ColorSpaceDielectricSpec`,
/// URP's `kDielectricSpec`): 4 % of linear light.
pub const DIELECTRIC: f32 = 0.04;
/// The built-in pipeline's dielectric reflectance in a gamma-space project, where its
/// shaders work on gamma-encoded values (0.04 encoded).
pub const DIELECTRIC_GAMMA: f32 = 0.220_916_3;

/// Which of Unity's formulas a scene's surfaces are shaded with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Brdf {
    /// The built-in pipeline's `BRDF1_Unity_PBS`: Disney diffuse; GGX, the Smith-joint
    /// visibility approximation and Schlick's Fresnel, in a gamma project the square root
    /// of the specular term, as its gamma-space shaders take it.
    BuiltIn { gamma: bool },
    /// URP's Lambert diffuse and `DirectBRDFSpecular`: GGX with a combined visibility and
    /// Fresnel approximation, without Fresnel's change with angle.
    Universal,
}

impl Brdf {
    /// The formula for a scene's pipeline (its lights' attenuation says which) and colour
    /// space.
    pub fn of(pipeline: Attenuation, space: ColorSpace) -> Brdf {
        match pipeline {
            Attenuation::Universal => Brdf::Universal,
            Attenuation::BuiltIn => Brdf::BuiltIn {
                gamma: space == ColorSpace::Gamma,
            },
        }
    }

    /// The share of a physically based surface's albedo (colour · (1 − metallic)) that
    /// its shader lights as diffuse: what the dielectric does not reflect
    /// (`OneMinusReflectivityFromMetallic`).
    pub fn diffuse_share(self) -> f32 {
        1.0 - self.dielectric()
    }

    /// The shape of the diffuse term at a point of smoothness `smoothness`, unit shading
    /// normal `n`, seen along unit `view`: the built-in pipeline's Disney term, URP's
    /// Lambert.
    pub fn diffuse(self, smoothness: f32, n: Vec3, view: Vec3) -> Diffuse {
        match self {
            Brdf::BuiltIn { .. } => Diffuse {
                slope: 1.0 - smoothness.clamp(0.0, 1.0),
                offset: -0.5,
                view_scatter: (1.0 - n.dot(view).abs()).powi(5),
            },
            Brdf::Universal => Diffuse::LAMBERT,
        }
    }

    fn dielectric(self) -> f32 {
        match self {
            Brdf::BuiltIn { gamma: true } => DIELECTRIC_GAMMA,
            _ => DIELECTRIC,
        }
    }

    /// What a point reflects of the environment (Unity's reflection probe), per unit of
    /// the probe's radiance, where its colour (times its texel) is `base`, its metallic
    /// value and smoothness `metallic` and `smoothness`, and `nv` the cosine between its
    /// shading normal and the direction towards the eye: the surface reduction times
    /// Fresnel's blend from f0 towards the grazing term, saturate(smoothness + 1 −
    /// (1 − dielectric)(1 − metallic)), by (1 − n·v)⁵ in the built-in pipeline
    /// (`BRDF1_Unity_PBS`) and (1 − n·v)⁴ in URP (`EnvironmentBRDFSpecular`).
    pub fn environment(self, base: Vec3, metallic: f32, smoothness: f32, nv: f32) -> Vec3 {
        let metallic = metallic.clamp(0.0, 1.0);
        let smoothness = smoothness.clamp(0.0, 1.0);
        let d = self.dielectric();
        let f0 = Vec3::splat(d).lerp(base, metallic);
        let grazing = (smoothness + 1.0 - (1.0 - d) * (1.0 - metallic)).min(1.0);
        let pr = 1.0 - smoothness;
        let (reduction, fresnel) = match self {
            Brdf::BuiltIn { gamma } => {
                let r = (pr * pr).max(0.002);
                let reduction = if gamma {
                    1.0 - 0.28 * r * pr
                } else {
                    1.0 / (r * r + 1.0)
                };
                (reduction, (1.0 - nv.abs().min(1.0)).powi(5))
            }
            Brdf::Universal => {
                let r = (pr * pr).max(0.007_812_5);
                let r2 = (r * r).max(6.103_515_6e-5);
                (1.0 / (r2 + 1.0), (1.0 - nv.clamp(0.0, 1.0)).powi(4))
            }
        };
        f0.lerp(Vec3::splat(grazing), fresnel) * reduction
    }

    /// The glossy side of a point whose colour (times its texel) is `base` and whose
    /// metallic value and smoothness are `metallic` and `smoothness`, with unit shading
    /// normal `n`, seen along unit `view` (from the point towards the eye).
    pub fn gloss(self, base: Vec3, metallic: f32, smoothness: f32, n: Vec3, view: Vec3) -> Gloss {
        let metallic = metallic.clamp(0.0, 1.0);
        let f0 = Vec3::splat(self.dielectric()).lerp(base, metallic);
        Gloss::new(self, f0, 1.0 - smoothness.clamp(0.0, 1.0), n, view)
    }
}

/// Whether lights can show on a material at all: its diffuse albedo is not black, or it
/// has highlights and its specular reflectance is not black (dielectrics reflect 4 %; only
/// a black surface fully metallic everywhere reflects nothing). Unlit shaders take no light.
pub fn shows_light(m: &Material) -> bool {
    !m.unlit
        && (m.albedo().max_element() > 0.0
            || (m.highlights && (m.least_metallic() < 1.0 || m.color.max_element() > 0.0)))
}

/// The shape of a shaded point's diffuse term: what multiplies albedo · cosine. The
/// built-in pipeline's `DisneyDiffuse` is (1 + (f90 − 1)(1 − n·l)⁵)(1 + (f90 − 1)(1 − n·v)⁵)
/// with f90 = 0.5 + 2(l·h)²·(1 − smoothness), which darkens smooth surfaces and brightens
/// rough ones towards grazing light and view; Lambert's (URP, and shaders that are not
/// physically based) is 1. Both are f90 − 1 = (1 + l·v)·`slope` + `offset`: Lambert's with
/// both 0, which gives exactly 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// 1 − smoothness for Disney's.
    slope: f32,
    /// −0.5 for Disney's.
    offset: f32,
    /// (1 − |n·v|)⁵.
    view_scatter: f32,
}

impl Diffuse {
    pub const LAMBERT: Diffuse = Diffuse {
        slope: 0.0,
        offset: 0.0,
        view_scatter: 0.0,
    };

    /// What albedo · `nl` is multiplied by for a light from a direction at cosine `nl` > 0
    /// with the normal and `lv` with the direction towards the eye.
    #[inline(always)]
    pub fn scale(&self, lv: f32, nl: f32) -> f32 {
        // 2(l·h)² = 1 + l·v: the half vector is never formed.
        let f90_less_1 = (1.0 + lv).max(0.0) * self.slope + self.offset;
        (1.0 + f90_less_1 * (1.0 - nl).powi(5)) * (1.0 + f90_less_1 * self.view_scatter)
    }
}

/// A shaded point's glossy reflection of the lights, with what its lobe's formula needs
/// of the point alone worked out once for all its lights.
#[derive(Clone, Copy, Debug)]
pub struct Gloss {
    /// Reflectance at normal incidence.
    pub f0: Vec3,
    lobe: Lobe,
}

#[derive(Clone, Copy, Debug)]
enum Lobe {
    /// Roughness a (at least 0.002), a², n·v and n·v·(1 − a) + a, the eye's share of the
    /// Smith-joint visibility's denominator.
    BuiltIn {
        a: f32,
        a2: f32,
        nv: f32,
        view_term: f32,
        gamma: bool,
    },
    /// Roughness² and URP's normalisation term 4r + 2.
    Universal { r2: f32, normalization: f32 },
}

impl Gloss {
    /// The gloss of `brdf` with reflectance `f0` and perceptual roughness (1 − smoothness)
    /// `pr`, at unit normal `n` seen along unit `view`.
    pub fn new(brdf: Brdf, f0: Vec3, pr: f32, n: Vec3, view: Vec3) -> Gloss {
        let lobe = match brdf {
            Brdf::BuiltIn { gamma } => {
                let a = (pr * pr).max(0.002);
                let nv = n.dot(view).abs();
                Lobe::BuiltIn {
                    a,
                    a2: a * a,
                    nv,
                    view_term: nv * (1.0 - a) + a,
                    gamma,
                }
            }
            Brdf::Universal => {
                // URP keeps its roughness above half precision's smallest normal values.
                let r = (pr * pr).max(0.007_812_5);
                Lobe::Universal {
                    r2: (r * r).max(6.103_515_6e-5),
                    normalization: r * 4.0 + 2.0,
                }
            }
        };
        Gloss { f0, lobe }
    }

    /// Whether the surface reflects any light specularly (Unity's shaders drop the term
    /// where f0 is black).
    pub fn any(&self) -> bool {
        self.f0.max_element() > 0.0
    }

    /// The light reflected towards the eye per unit of a light's radiance arriving from
    /// unit direction `l` at cosine `nl` > 0 with the normal, the cosine included; `n` and
    /// `view` are the ones the gloss was made for (not kept in it: a shaded point's record
    /// holds them once).
    #[inline(always)]
    pub fn highlight(&self, n: Vec3, view: Vec3, l: Vec3, nl: f32) -> Vec3 {
        // Unity's `SafeNormalize`: a light straight behind the eye gives no half vector.
        // The half vector is never formed: n·h and l·h are scaled dot products.
        let sum = l + view;
        let inv = sum.length_squared().max(0.001).sqrt().recip();
        let nh = (n.dot(sum) * inv).clamp(0.0, 1.0);
        let lh = (l.dot(sum) * inv).clamp(0.0, 1.0);
        match self.lobe {
            Lobe::BuiltIn {
                a,
                a2,
                nv,
                view_term,
                gamma,
            } => {
                // V·D·π = 0.5/(λv + λl + 1e-5) · a²/(π(d² + 1e-7)) · π, in one division.
                let lambda_v = nl * view_term;
                let lambda_l = nv * (nl * (1.0 - a) + a);
                let d = (nh * a2 - nh) * nh + 1.0;
                let mut term = 0.5 * a2 / ((lambda_v + lambda_l + 1e-5) * (d * d + 1e-7));
                if gamma {
                    term = term.max(1e-4).sqrt();
                }
                let term = (term * nl).max(0.0);
                let schlick = (1.0 - lh).powi(5);
                (self.f0 + (Vec3::ONE - self.f0) * schlick) * term
            }
            Lobe::Universal { r2, normalization } => {
                let d = nh * nh * (r2 - 1.0) + 1.00001;
                let term = r2 / ((d * d) * (lh * lh).max(0.1) * normalization);
                self.f0 * (term * nl)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use formats::texture::{TextureRef, Tiling};
    use formats::MetallicMap;
    use std::f32::consts::PI;

    #[test]
    fn environment_reflection_follows_each_pipelines_formula() {
        let built_in = Brdf::BuiltIn { gamma: false };
        let grey = Vec3::splat(0.5);
        let near = |a: Vec3, b: f32| (a - Vec3::splat(b)).abs().max_element() < 1e-6;
        // Smoothness 0.5: roughness 0.25, surface reduction 1/(0.25² + 1); grazing 0.54.
        let reduction = 1.0 / 1.0625;
        assert!(near(
            built_in.environment(grey, 0.0, 0.5, 1.0),
            0.04 * reduction
        ));
        let fifth = 0.5f32.powi(5);
        let want = (0.04 + 0.5 * fifth) * reduction;
        assert!(near(built_in.environment(grey, 0.0, 0.5, 0.5), want));
        assert!(
            near(built_in.environment(grey, 0.0, 0.5, -0.5), want),
            "|n·v|"
        );
        let fourth = 0.5f32.powi(4);
        let urp = Brdf::Universal.environment(grey, 0.0, 0.5, 0.5);
        assert!(near(urp, (0.04 + 0.5 * fourth) * reduction));
        assert!(near(
            Brdf::Universal.environment(grey, 0.0, 0.5, -0.5),
            0.54 * reduction
        ));
        // A smooth metal reflects its colour head-on, white at grazing angles.
        let gold = Vec3::new(0.8, 0.6, 0.2);
        // (Unity keeps the roughness at 0.002 or more.)
        let smooth = 1.0 / (0.002f32 * 0.002 + 1.0);
        let head_on = built_in.environment(gold, 1.0, 1.0, 1.0);
        assert!((head_on - gold * smooth).abs().max_element() < 1e-6);
        assert!(near(built_in.environment(gold, 1.0, 1.0, 0.0), smooth));
        // A gamma project's shaders: the encoded dielectric and 1 − 0.28·r·p.
        let gamma = Brdf::BuiltIn { gamma: true }.environment(grey, 0.0, 0.5, 1.0);
        assert!(near(gamma, DIELECTRIC_GAMMA * (1.0 - 0.28 * 0.25 * 0.5)));
    }

    /// A gloss on a surface facing +Y, seen along `view`.
    struct Seen {
        gloss: Gloss,
        view: Vec3,
    }

    impl Seen {
        fn highlight(&self, l: Vec3, nl: f32) -> Vec3 {
            self.gloss.highlight(Vec3::Y, self.view, l, nl)
        }
    }

    fn gloss(brdf: Brdf, f0: f32, smoothness: f32, view: Vec3) -> Seen {
        let view = view.normalize();
        Seen {
            gloss: Gloss::new(brdf, Vec3::splat(f0), 1.0 - smoothness, Vec3::Y, view),
            view,
        }
    }

    const BUILT_IN: Brdf = Brdf::BuiltIn { gamma: false };

    /// Light, normal and eye in one line: n·h = l·h = n·v = 1, where each formula reduces
    /// to a closed form.
    #[test]
    fn head_on_peaks_match_the_closed_forms() {
        let n = Vec3::Y;
        for smoothness in [0.0f32, 0.5, 0.9] {
            let a = (1.0 - smoothness).powi(2);
            // Built-in: D = 1/(π a²), V = 0.5/(2 + 1e-5), F = f0, times π.
            let g = gloss(BUILT_IN, 0.04, smoothness, n);
            let want = 0.04 * PI * (0.5 / (2.0 + 1e-5)) * (a * a / (PI * (a.powi(4) + 1e-7)));
            let got = g.highlight(n, 1.0).x;
            assert!(
                (got - want).abs() <= 1e-4 * want,
                "{smoothness}: {got} vs {want}"
            );
            // URP: r²/(d²·1·(4r + 2)) with d = r² + 0.00001.
            let g = gloss(Brdf::Universal, 0.04, smoothness, n);
            let r2 = a * a;
            let d = r2 + 0.00001;
            let want = 0.04 * r2 / (d * d * (4.0 * a + 2.0));
            let got = g.highlight(n, 1.0).x;
            // 1.00001 + (r² − 1) loses the low digits of r² in f32.
            assert!(
                (got - want).abs() <= 1e-3 * want,
                "{smoothness}: {got} vs {want}"
            );
        }
        // Smoothness 0.5 on a dielectric: about a fifth of the diffuse white's light.
        let urp = gloss(Brdf::Universal, 0.04, 0.5, n).highlight(n, 1.0).x;
        assert!((urp - 0.2123).abs() < 1e-3, "{urp}");
    }

    /// The two pipelines approximate one lobe differently: URP's combined visibility and
    /// Fresnel term, 1/((4r + 2)·(l·h)²), is brighter at the peak than the built-in's
    /// Smith-joint visibility (1/4 head-on), by 4/3 at smoothness 0.5 and towards twice as
    /// the surface grows smooth.
    #[test]
    fn pipelines_differ_as_their_formulas_say() {
        let n = Vec3::Y;
        let l = Vec3::new(0.3, 1.0, 0.0).normalize();
        let mirror = Vec3::new(-0.3, 1.0, 0.0);
        for (view, smoothness, low, high) in [
            (mirror, 0.5, 1.25, 1.45),
            (mirror, 0.8, 1.75, 1.95),
            (Vec3::new(-0.5, 1.0, 0.4), 0.5, 1.2, 1.45),
        ] {
            let b = gloss(BUILT_IN, 0.04, smoothness, view).highlight(l, n.dot(l));
            let u = gloss(Brdf::Universal, 0.04, smoothness, view).highlight(l, n.dot(l));
            let ratio = u.x / b.x;
            assert!((low..high).contains(&ratio), "{view} {smoothness}: {ratio}");
        }
    }

    /// Away from the mirror direction a smooth surface's highlight falls off; a rough one
    /// spreads it.
    #[test]
    fn smooth_lobes_are_narrow() {
        let n = Vec3::Y;
        let l = Vec3::new(1.0, 1.0, 0.0).normalize();
        let mirror = Vec3::new(-1.0, 1.0, 0.0);
        let off = Vec3::new(-1.0, 1.0, 0.6);
        for brdf in [BUILT_IN, Brdf::Universal] {
            let peak = gloss(brdf, 0.04, 0.9, mirror).highlight(l, n.dot(l)).x;
            let side = gloss(brdf, 0.04, 0.9, off).highlight(l, n.dot(l)).x;
            assert!(side < peak * 0.05, "{brdf:?}: {side} vs {peak}");
            let peak = gloss(brdf, 0.04, 0.0, mirror).highlight(l, n.dot(l)).x;
            let side = gloss(brdf, 0.04, 0.0, off).highlight(l, n.dot(l)).x;
            assert!(side > peak * 0.5, "{brdf:?}: {side} vs {peak}");
        }
    }

    /// A perfectly smooth metal lit and seen from the mirror direction stays finite, and
    /// grazing or opposite directions give no NaN.
    #[test]
    fn extremes_stay_finite() {
        let n = Vec3::Y;
        for brdf in [BUILT_IN, Brdf::BuiltIn { gamma: true }, Brdf::Universal] {
            for (l, v) in [
                (Vec3::Y, Vec3::Y),
                (Vec3::new(1.0, 1e-6, 0.0), Vec3::new(-1.0, 1e-6, 0.0)),
                (Vec3::new(1.0, 1e-3, 0.0), Vec3::new(1.0, 1e-3, 0.0)),
                (Vec3::new(1.0, 1e-7, 0.0), Vec3::new(-1.0, -1e-7, 0.0)),
            ] {
                let l = l.normalize();
                let h = gloss(brdf, 1.0, 1.0, v).highlight(l, n.dot(l).max(1e-7));
                assert!(
                    h.is_finite() && h.min_element() >= 0.0,
                    "{brdf:?} {l} {v}: {h}"
                );
            }
        }
    }

    /// Schlick's Fresnel brightens a built-in dielectric towards grazing light; URP's
    /// formula has no such term.
    #[test]
    fn built_in_fresnel_rises_at_grazing() {
        let n = Vec3::Y;
        let l = Vec3::new(1.0, 0.05, 0.0).normalize();
        let v = Vec3::new(-1.0, 0.05, 0.0);
        let dielectric = gloss(BUILT_IN, 0.04, 0.5, v).highlight(l, n.dot(l));
        let metal = gloss(BUILT_IN, 1.0, 0.5, v).highlight(l, n.dot(l));
        // l·h = cos 87° ≈ 0.05: F = 0.04 + 0.96 · 0.95⁵ ≈ 0.78 of the metal's.
        let ratio = dielectric.x / metal.x;
        assert!((ratio - 0.783).abs() < 0.01, "{ratio}");
    }

    /// The Disney term without the half vector agrees with Unity's `DisneyDiffuse`, which
    /// forms it, at grazing and head-on light and view; URP's diffuse is Lambert's. The
    /// diffuse share is what a dielectric does not reflect.
    #[test]
    fn disney_diffuse_follows_unitys_formula_at_every_angle() {
        let unity = |n: Vec3, l: Vec3, v: Vec3, pr: f32| {
            let h = (l + v).normalize();
            let lh = l.dot(h).clamp(0.0, 1.0);
            let (nl, nv) = (n.dot(l).clamp(0.0, 1.0), n.dot(v).abs());
            let fd90 = 0.5 + 2.0 * lh * lh * pr;
            (1.0 + (fd90 - 1.0) * (1.0 - nl).powi(5)) * (1.0 + (fd90 - 1.0) * (1.0 - nv).powi(5))
        };
        let n = Vec3::Y;
        let dir = |deg: f32, az: f32| {
            let (t, a) = (deg.to_radians(), az.to_radians());
            Vec3::new(t.sin() * a.cos(), t.cos(), t.sin() * a.sin())
        };
        let built_in = Brdf::of(Attenuation::BuiltIn, ColorSpace::Linear);
        let mut spread = (f32::MAX, f32::MIN);
        for pr in [0.0f32, 0.3, 0.5, 1.0] {
            for (lt, la) in [(0.0, 0.0), (45.0, 0.0), (80.0, 90.0), (89.0, 180.0)] {
                for (vt, va) in [(0.0, 0.0), (60.0, 30.0), (85.0, 0.0), (89.5, 180.0)] {
                    let (l, v) = (dir(lt, la), dir(vt, va));
                    let want = unity(n, l, v, pr);
                    let got = built_in.diffuse(1.0 - pr, n, v).scale(l.dot(v), n.dot(l));
                    assert!((got - want).abs() < 1e-5, "{pr} {l} {v}: {got} vs {want}");
                    spread = (spread.0.min(got), spread.1.max(got));
                    let urp = Brdf::Universal.diffuse(1.0 - pr, n, v);
                    assert_eq!(urp.scale(l.dot(v), n.dot(l)), 1.0);
                }
            }
        }
        // Smooth surfaces darken towards grazing angles (to a quarter), rough ones brighten
        // (to about 2.5²).
        assert!(spread.0 < 0.3 && spread.1 > 5.0, "{spread:?}");
        assert_eq!(built_in.diffuse_share(), 0.96);
        assert_eq!(Brdf::Universal.diffuse_share(), 0.96);
        let gamma = Brdf::of(Attenuation::BuiltIn, ColorSpace::Gamma);
        assert_eq!(gamma.diffuse_share(), 1.0 - DIELECTRIC_GAMMA);
    }

    #[test]
    fn gloss_mixes_dielectric_and_colour_by_metallic() {
        let mut m = Material::unity_default();
        m.metallic = 0.5;
        m.smoothness = 0.75;
        let built_in = Brdf::of(Attenuation::BuiltIn, ColorSpace::Linear);
        let g = built_in.gloss(Vec3::new(1.0, 0.0, 0.0), 0.5, 0.75, Vec3::Y, Vec3::Y);
        assert_eq!(g.f0, Vec3::new(0.52, 0.02, 0.02));
        // Roughness (1 − 0.75)² = 1/16, so a² = 1/256 and, head-on, d = a².
        let a2 = 1.0f32 / 256.0;
        let want = 0.5 * a2 / ((2.0 + 1e-5) * (a2 * a2 + 1e-7));
        let peak = g.highlight(Vec3::Y, Vec3::Y, Vec3::Y, 1.0).x / 0.52;
        assert!((peak - want).abs() < 1e-4 * want, "{peak} vs {want}");
        let gamma = Brdf::of(Attenuation::BuiltIn, ColorSpace::Gamma);
        let zero = Vec3::ZERO;
        let f0 = gamma.gloss(zero, 0.5, 0.75, Vec3::Y, Vec3::Y).f0.x;
        assert_eq!(f0, DIELECTRIC_GAMMA * 0.5);
        let urp = Brdf::of(Attenuation::Universal, ColorSpace::Gamma);
        assert_eq!(urp.gloss(zero, 0.5, 0.75, Vec3::Y, Vec3::Y).f0.x, 0.02);
        m.metallic = 1.0;
        m.color = Vec3::ZERO;
        assert!(!shows_light(&m));
        // A metallic map may hold dielectric texels, which reflect 4 % of white light.
        m.metallic_map = Some(MetallicMap {
            map: TextureRef {
                texture: 0,
                tiling: Tiling::default(),
            },
            smoothness: 0.5,
        });
        assert!(shows_light(&m));
        m.metallic_map = None;
        m.metallic = 0.99;
        assert!(shows_light(&m));
        m.highlights = false;
        assert!(!shows_light(&m));
    }
}
