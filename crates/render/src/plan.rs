//! The effects plan: before tracing, decide from the soup which effects can change the
//! image, and why. The integrator consults it, so a ray that cannot change the image is
//! never traced; it is printed, stored in the EXR header and returned in `--json`.

use crate::alpha::{alpha_use, min_alphas, AlphaUse};
use crate::brdf::shows_light;
use crate::probe::{Probe, LEVELS, RESOLUTION};
use crate::{RenderOptions, TextureFilter};
use formats::{
    AmbientMode, Attenuation, CastShadows, ClearFlags, Cull, Fog, FogMode, LightKind, Material,
    Panorama, Shadows, Sky, SkyLayout, Soup,
};
use glam::Vec3;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ShadowMode {
    None,
    Hard,
    Soft,
}

#[derive(Clone, Debug, Serialize)]
pub struct LightPlan {
    pub name: String,
    pub kind: &'static str,
    /// Whether the light is evaluated at all.
    pub enabled: bool,
    pub shadows: ShadowMode,
    /// Shadow rays per shading point (0, 1, or --soft-samples).
    pub shadow_rays: u32,
    pub reason: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct Effect {
    pub enabled: bool,
    pub reason: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct ReflectionPlan {
    pub enabled: bool,
    /// Maximum bounces (0 when disabled).
    pub depth: u32,
    pub cutoff: f32,
    pub reflective_materials: usize,
    pub reason: String,
}

/// The skybox reflected by physically based surfaces, as Unity's default reflection probe
/// holds it: on when the scene reflects its skybox and a used material is physically based.
#[derive(Clone, Debug, Serialize)]
pub struct SkyReflectionPlan {
    pub enabled: bool,
    pub reason: String,
    /// The probe's levels the used materials read: the renderer builds these alone.
    #[serde(skip)]
    pub levels: [bool; LEVELS],
}

#[derive(Clone, Debug, Serialize)]
pub struct AntiAliasing {
    pub enabled: bool,
    pub spp: u32,
    pub pattern: &'static str,
    pub reason: String,
}

/// Which surfaces camera and reflection rays pass through: faces their material culls and
/// shadows-only objects, refused inside the traversal (counted as pass-throughs).
#[derive(Clone, Debug, Serialize)]
pub struct CullPlan {
    pub enabled: bool,
    /// Used materials that cull a face (`_Cull` front or back).
    pub culling_materials: usize,
    /// Objects with `m_CastShadows` shadows only.
    pub shadows_only: usize,
    pub reason: String,
}

/// Whether shadow rays must look past surfaces that do not cast (`m_CastShadows` off, or
/// a face the material culls seen from the light): then each hit a shadow ray finds is
/// asked whether it casts, and the ray stops at the first that does.
#[derive(Clone, Debug, Serialize)]
pub struct ShadowCastPlan {
    pub enabled: bool,
    /// Objects with `m_CastShadows` off.
    pub non_casting: usize,
    /// Used materials whose culled faces cast no shadow (on objects casting "on").
    pub culled_in_shadow_pass: usize,
    /// Used unlit materials: their shaders have no shadow-caster pass.
    pub unlit_materials: usize,
    /// Objects with `m_ReceiveShadows` off: no shadow rays leave them.
    pub not_receiving: usize,
    pub reason: String,
}

/// Albedo textures: on when a used material with a diffuse colour has a map. Off, no UV
/// is interpolated and no texel read.
#[derive(Clone, Debug, Serialize)]
pub struct TexturePlan {
    pub enabled: bool,
    /// Used materials whose albedo is looked up in a map.
    pub textured_materials: usize,
    /// Distinct textures those materials, the alpha lookups, and the normal and emission
    /// maps read.
    pub textures: usize,
    /// Bytes of those textures' mip levels below the full-size images, which the soup
    /// holds (linear RGBA f32).
    pub bytes: u64,
    pub filter: TextureFilter,
    pub reason: String,
    /// Which of the soup's textures those are: the renderer builds mip levels for these
    /// alone.
    #[serde(skip)]
    pub read: Vec<bool>,
}

/// Normal maps: on when a used material has one and its shading normal can change the
/// image: it takes direct light or an ambient that depends on the normal (trilight, sky)
/// on a diffuse albedo, it mirrors, or the normal AOV is written. Off, no normal map is
/// read and shading uses the interpolated vertex normal.
#[derive(Clone, Debug, Serialize)]
pub struct NormalMapPlan {
    pub enabled: bool,
    /// Used materials whose shading normal is looked up in a map.
    pub materials: usize,
    pub reason: String,
}

/// Alpha: on when a used material is cut out where its α can fall below the cut-off, or
/// blended where α can be below 1.
#[derive(Clone, Debug, Serialize)]
pub struct AlphaPlan {
    pub enabled: bool,
    pub cutout_materials: usize,
    pub blend_materials: usize,
    pub reason: String,
    /// Each soup texture's least texel alpha (0–1), which decides how a material with a
    /// map uses alpha ([`alpha_use`]); found once, here, for the renderer too.
    #[serde(skip)]
    pub min_alpha: Vec<f32>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    /// Direct lighting: on when some light is on and some material shows light (a diffuse
    /// albedo or a highlight).
    pub direct: Effect,
    pub lights: Vec<LightPlan>,
    pub culling: CullPlan,
    pub shadow_casting: ShadowCastPlan,
    pub textures: TexturePlan,
    pub normal_maps: NormalMapPlan,
    pub alpha: AlphaPlan,
    pub reflections: ReflectionPlan,
    pub ambient: Effect,
    pub sky_reflections: SkyReflectionPlan,
    pub emission: Effect,
    /// RenderSettings fog: on when the scene has fog that can thin a surface's colour.
    pub fog: Effect,
    pub anti_aliasing: AntiAliasing,
    pub background: String,
}

fn vec(v: Vec3) -> String {
    format!("({:.3}, {:.3}, {:.3})", v.x, v.y, v.z)
}

/// An image sky's images, for the plan.
fn sky_images(layout: &SkyLayout) -> String {
    match layout {
        SkyLayout::LatLong { image, panorama } => format!(
            "latitude-longitude sky {} ({}x{}{})",
            image.source,
            image.width,
            image.height,
            match panorama {
                Panorama::Full => "",
                Panorama::Half => ", 180°, black behind",
                Panorama::HalfMirrored => ", 180°, mirrored behind",
            }
        ),
        SkyLayout::Cube { faces } => format!(
            "cube sky of {} faces ({}x{} first)",
            faces.len(),
            faces.first().map_or(0, |f| f.width),
            faces.first().map_or(0, |f| f.height)
        ),
    }
}

impl Plan {
    pub fn derive(soup: &Soup, opts: &RenderOptions) -> Plan {
        // Only materials that some triangle uses can change the image.
        let mut used = vec![false; soup.materials.len()];
        for &m in &soup.tri_material {
            if let Some(u) = used.get_mut(m as usize) {
                *u = true;
            }
        }
        let mats: Vec<_> = soup
            .materials
            .iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .map(|(m, _)| m)
            .collect();
        let diffuse = mats
            .iter()
            .any(|m| !m.unlit && m.albedo().max_element() > 0.0);
        let glossy_or_diffuse = mats.iter().any(|m| shows_light(m));

        let lights: Vec<LightPlan> = soup
            .lights
            .iter()
            .map(|l| light_plan(l, glossy_or_diffuse, opts))
            .map(|mut l| {
                if let (Some(reach), true) = (shadow_reach(soup), l.shadows != ShadowMode::None) {
                    l.reason += &reach;
                }
                l
            })
            .collect();
        let lit = lights.iter().filter(|l| l.enabled).count();
        let direct = Effect {
            enabled: lit > 0,
            reason: if soup.lights.is_empty() {
                "the scene has no lights".into()
            } else if !glossy_or_diffuse {
                "no material shows light (each is unlit, or black and fully metallic)".into()
            } else if lit == 0 {
                "no light delivers any light".into()
            } else {
                format!("{lit} of {} lights contribute", soup.lights.len())
            },
        };

        // A material whose reflectance reaches the cut-off sends mirror rays.
        let mirror =
            |m: &Material| m.reflectance().max_element() >= opts.cutoff.max(f32::MIN_POSITIVE);
        let reflective = mats.iter().filter(|m| mirror(m)).count();
        let reflections = if opts.depth == 0 {
            ReflectionPlan {
                enabled: false,
                depth: 0,
                cutoff: opts.cutoff,
                reflective_materials: reflective,
                reason: "--depth 0".into(),
            }
        } else if reflective == 0 {
            ReflectionPlan {
                enabled: false,
                depth: 0,
                cutoff: opts.cutoff,
                reflective_materials: 0,
                reason: format!("no material has a reflectance ≥ {}", opts.cutoff),
            }
        } else {
            ReflectionPlan {
                enabled: true,
                depth: opts.depth,
                cutoff: opts.cutoff,
                reflective_materials: reflective,
                reason: format!(
                    "{reflective} reflective materials; rays stop at depth {} or when the \
                     path weight falls below {}",
                    opts.depth, opts.cutoff
                ),
            }
        };

        let amb = &soup.environment.ambient;
        // Skybox ambient is the procedural sky's light where the scene has one.
        let sky_lit = amb.mode == AmbientMode::Skybox && soup.environment.sky.is_some();
        let ambient_on = match amb.mode {
            AmbientMode::Flat => amb.sky.max_element() > 0.0,
            _ if sky_lit => amb.intensity > 0.0,
            AmbientMode::Trilight | AmbientMode::Skybox => {
                amb.sky.max(amb.equator).max(amb.ground).max_element() > 0.0
            }
        };
        let ambient = Effect {
            enabled: ambient_on && diffuse,
            reason: if !ambient_on {
                "the ambient light is black".into()
            } else if !diffuse {
                "no material has a diffuse albedo".into()
            } else if sky_lit {
                format!(
                    "skybox ambient: the skybox's light in nine spherical harmonics, \
                     intensity {}",
                    amb.intensity
                )
            } else {
                match amb.mode {
                    AmbientMode::Flat => format!("flat ambient {}", vec(amb.sky)),
                    _ => format!(
                        "{:?} ambient: sky {}, equator {}, ground {}",
                        amb.mode,
                        vec(amb.sky),
                        vec(amb.equator),
                        vec(amb.ground)
                    ),
                }
            },
        };

        let sky_reflections = sky_reflection_plan(soup, &mats);

        let glowing: Vec<&Material> = mats
            .iter()
            .filter(|m| m.emission.max_element() > 0.0)
            .copied()
            .collect();
        let emissive = glowing.len();
        let emission_mapped = glowing.iter().filter(|m| m.emission_map.is_some()).count();
        let emission = Effect {
            enabled: emissive > 0,
            reason: if emissive > 0 {
                format!("{emissive} emissive materials ({emission_mapped} with emission maps)")
            } else {
                "no material emits".into()
            },
        };

        let fog = fog_plan(soup.environment.fog.as_ref());

        let anti_aliasing = AntiAliasing {
            enabled: opts.spp > 1,
            spp: opts.spp,
            pattern: if opts.spp <= 1 {
                "pixel centre"
            } else if is_square(opts.spp) {
                "jittered grid, box filter"
            } else {
                "Latin hypercube, box filter"
            },
            reason: if opts.spp > 1 {
                format!("--spp {}", opts.spp)
            } else {
                "--spp 1".into()
            },
        };

        let background = match soup.environment.clear {
            ClearFlags::SolidColor => format!("solid colour {}", vec(soup.environment.background)),
            ClearFlags::Skybox => match &soup.environment.sky {
                Some(Sky::Procedural(sky)) => format!(
                    "Unity's procedural sky: sun disk {:?}, atmosphere thickness {}, exposure \
                     {}, towards the sun {}",
                    sky.sun_disk,
                    sky.atmosphere_thickness,
                    sky.exposure,
                    vec(sky.sun_direction)
                ),
                Some(Sky::Textured(sky)) => format!(
                    "{}, times {}, turned {}°",
                    sky_images(&sky.layout),
                    vec(sky.scale),
                    sky.rotation
                ),
                None => "sky gradient".into(),
            },
        };

        // The shading normal shows through direct light, an ambient that depends on it,
        // a mirror's direction, or the normal AOV.
        let diffuse_normal = ambient.enabled && soup.environment.ambient.mode != AmbientMode::Flat;
        let normal_mapped: Vec<&Material> = mats
            .iter()
            .filter(|m| {
                m.normal_map.is_some()
                    && !m.unlit
                    && (opts.aovs.normal
                        || (direct.enabled && shows_light(m))
                        || (diffuse_normal && m.albedo().max_element() > 0.0)
                        || (sky_reflections.enabled && m.pbs)
                        || (reflections.enabled && mirror(m)))
            })
            .copied()
            .collect();
        let normal_maps = NormalMapPlan {
            enabled: !normal_mapped.is_empty(),
            materials: normal_mapped.len(),
            reason: if !normal_mapped.is_empty() {
                format!(
                    "{} materials with normal maps, read with the albedo's filter",
                    normal_mapped.len()
                )
            } else if mats.iter().any(|m| m.normal_map.is_some()) {
                "no light, mirror or AOV shows the normal-mapped materials' normals".into()
            } else {
                "no material has a normal map".into()
            },
        };

        // Occlusion maps darken the ambient light on diffuse surfaces and the reflections
        // of mirrors; elsewhere they change nothing.
        let occluded: Vec<&Material> = mats
            .iter()
            .filter(|m| {
                m.occlusion_map.is_some()
                    && !m.unlit
                    && ((ambient.enabled && m.albedo().max_element() > 0.0)
                        || (sky_reflections.enabled && m.pbs)
                        || (reflections.enabled && mirror(m)))
            })
            .copied()
            .collect();
        let mut ambient = ambient;
        if !occluded.is_empty() {
            ambient.reason += &format!(
                "; {} materials darken it and their reflections by occlusion maps",
                occluded.len()
            );
        }

        // Metallic maps set how much of a surface's light is diffuse, glossy or mirrored:
        // they show wherever it is lit or mirrors at all, and in the albedo AOV.
        let metal_mapped: Vec<&Material> = mats
            .iter()
            .filter(|m| {
                m.metallic_map.is_some()
                    && !m.unlit
                    && (opts.aovs.albedo
                        || (direct.enabled && shows_light(m))
                        || (ambient.enabled && m.albedo().max_element() > 0.0)
                        || (sky_reflections.enabled && m.pbs)
                        || (reflections.enabled && mirror(m)))
            })
            .copied()
            .collect();

        let (culling, shadow_casting) = draw_rules(soup, &used, &lights);
        // Maps read besides the albedo maps: normal maps that show, the emission maps of
        // glowing materials, occlusion maps where ambient light or a mirror shows them, and
        // metallic maps where the surface shows light.
        let other_maps: Vec<u32> = normal_mapped
            .iter()
            .filter_map(|m| m.normal_map.map(|n| n.map.texture))
            .chain(
                glowing
                    .iter()
                    .filter_map(|m| m.emission_map.map(|r| r.texture)),
            )
            .chain(
                occluded
                    .iter()
                    .filter_map(|m| m.occlusion_map.map(|o| o.map.texture)),
            )
            .chain(
                metal_mapped
                    .iter()
                    .filter_map(|m| m.metallic_map.map(|g| g.map.texture)),
            )
            .collect();
        let (mut textures, alpha) = texturing(soup, &mats, &other_maps, opts.texture_filter);
        if !metal_mapped.is_empty() {
            textures.reason += &format!(
                "; {} materials take metallic and smoothness from metallic maps",
                metal_mapped.len()
            );
        }

        Plan {
            direct,
            lights,
            culling,
            shadow_casting,
            textures,
            normal_maps,
            alpha,
            reflections,
            ambient,
            sky_reflections,
            emission,
            fog,
            anti_aliasing,
            background,
        }
    }

    /// Human-readable, one effect per line.
    pub fn describe(&self) -> String {
        let on = |b: bool| if b { "on " } else { "off" };
        let mut s = String::from("effects plan:\n");
        s += &format!(
            "  direct light   {}  {}\n",
            on(self.direct.enabled),
            self.direct.reason
        );
        for l in &self.lights {
            s += &format!(
                "    light {:?} ({}): {}, shadows {:?} ({} rays/point): {}\n",
                l.name,
                l.kind,
                if l.enabled { "on" } else { "off" },
                l.shadows,
                l.shadow_rays,
                l.reason
            );
        }
        s += &format!(
            "  culling        {}  {}\n",
            on(self.culling.enabled),
            self.culling.reason
        );
        s += &format!(
            "  shadow casting {}  {}\n",
            on(self.shadow_casting.enabled),
            self.shadow_casting.reason
        );
        s += &format!(
            "  textures       {}  {}\n",
            on(self.textures.enabled),
            self.textures.reason
        );
        s += &format!(
            "  normal maps    {}  {}\n",
            on(self.normal_maps.enabled),
            self.normal_maps.reason
        );
        s += &format!(
            "  alpha          {}  {}\n",
            on(self.alpha.enabled),
            self.alpha.reason
        );
        s += &format!(
            "  reflections    {}  {}\n",
            on(self.reflections.enabled),
            self.reflections.reason
        );
        s += &format!(
            "  ambient        {}  {}\n",
            on(self.ambient.enabled),
            self.ambient.reason
        );
        s += &format!(
            "  sky reflection {}  {}\n",
            on(self.sky_reflections.enabled),
            self.sky_reflections.reason
        );
        s += &format!(
            "  emission       {}  {}\n",
            on(self.emission.enabled),
            self.emission.reason
        );
        s += &format!(
            "  fog            {}  {}\n",
            on(self.fog.enabled),
            self.fog.reason
        );
        s += &format!(
            "  anti-aliasing  {}  {} ({})\n",
            on(self.anti_aliasing.enabled),
            self.anti_aliasing.reason,
            self.anti_aliasing.pattern
        );
        s += &format!("  background     {}", self.background);
        s
    }

    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
}

/// Physically based surfaces reflect the skybox where the scene's default reflection
/// probe holds it (a skybox the soup holds, and an intensity above 0).
fn sky_reflection_plan(soup: &Soup, mats: &[&Material]) -> SkyReflectionPlan {
    let env = &soup.environment;
    let pbs: Vec<&Material> = mats.iter().filter(|m| m.pbs && !m.unlit).copied().collect();
    let constant = pbs.iter().filter(|m| !m.reflections).count();
    let off = |reason: &str| SkyReflectionPlan {
        enabled: false,
        reason: reason.into(),
        levels: [false; LEVELS],
    };
    if env.sky.is_none() {
        off("the scene reflects no skybox the soup holds")
    } else if env.reflection <= 0.0 {
        off("the environment reflection's intensity is 0")
    } else if pbs.is_empty() {
        off("no material is physically based")
    } else {
        SkyReflectionPlan {
            enabled: true,
            reason: format!(
                "{} physically based materials reflect the skybox as Unity's default \
                 reflection probe holds it ({RESOLUTION}² a face, each level prefiltered for \
                 its roughness), intensity {}{}",
                pbs.len(),
                env.reflection,
                if constant > 0 {
                    format!("; {constant} with Reflections off reflect its mean colour")
                } else {
                    String::new()
                }
            ),
            levels: Probe::levels_read(pbs.iter().map(|m| m.smoothness_range())),
        }
    }
}

/// Fog is on when the scene has some and it thins what lies at some distance: an
/// exponential fog of density 0 never does.
fn fog_plan(fog: Option<&Fog>) -> Effect {
    let Some(fog) = fog else {
        return Effect {
            enabled: false,
            reason: "the scene has no fog".into(),
        };
    };
    let colour = vec(fog.colour);
    // A negative density is squared away by the squared mode, but leaves the plain one
    // clear: its factor exceeds 1 and is clamped.
    match fog.mode {
        FogMode::Exponential { density } | FogMode::ExponentialSquared { density }
            if density == 0.0 =>
        {
            Effect {
                enabled: false,
                reason: "fog density 0".into(),
            }
        }
        FogMode::Exponential { density } if density < 0.0 => Effect {
            enabled: false,
            reason: format!("exponential fog of negative density {density} is clear"),
        },
        FogMode::Linear { start, end } => Effect {
            enabled: true,
            reason: format!("linear fog from {start} to {end} m, colour {colour}"),
        },
        FogMode::Exponential { density } => Effect {
            enabled: true,
            reason: format!("exponential fog, density {density}, colour {colour}"),
        },
        FogMode::ExponentialSquared { density } => Effect {
            enabled: true,
            reason: format!("exponential squared fog, density {density}, colour {colour}"),
        },
    }
}

/// Whether material `m` reads its albedo map for colour: it has one and a colour the map
/// can show in, diffuse or a metal's highlight (a black tint stays black whatever the
/// texel).
pub fn colour_mapped(m: &Material) -> bool {
    m.albedo_map.is_some() && m.color.max_element() > 0.0
}

/// The texture and alpha effects the used materials `mats` call for; the textures
/// `other_maps` (normal and emission maps) are read too.
fn texturing(
    soup: &Soup,
    mats: &[&Material],
    other_maps: &[u32],
    filter: TextureFilter,
) -> (TexturePlan, AlphaPlan) {
    let min_alpha = min_alphas(&soup.textures);
    let uses: Vec<AlphaUse> = mats.iter().map(|m| alpha_use(m, &min_alpha)).collect();
    let cutout_materials = uses
        .iter()
        .filter(|u| matches!(u, AlphaUse::Cutout { .. }))
        .count();
    let blend_materials = uses.iter().filter(|u| **u == AlphaUse::Blend).count();
    let alpha_on = cutout_materials + blend_materials > 0;
    let textured_materials = mats.iter().filter(|m| colour_mapped(m)).count();
    // Textures read at all: for colour, or for the alpha of a material that uses it.
    let mut read = vec![false; soup.textures.len()];
    for (m, u) in mats.iter().zip(&uses) {
        if let Some(r) = m
            .albedo_map
            .filter(|_| colour_mapped(m) || *u != AlphaUse::Opaque)
        {
            if let Some(x) = read.get_mut(r.texture as usize) {
                *x = true;
            }
        }
    }
    for &t in other_maps {
        if let Some(x) = read.get_mut(t as usize) {
            *x = true;
        }
    }
    let textures = read.iter().filter(|&&r| r).count();
    let bytes: u64 = soup
        .textures
        .iter()
        .zip(&read)
        .filter(|(_, &r)| r)
        .map(|(t, _)| crate::texture::sampler_bytes(t))
        .sum();
    let how = match filter {
        TextureFilter::Cone => "each texture's own filter and mip maps, the level from a ray cone",
        TextureFilter::Bilinear => "bilinear on the full-size images (--texture-filter bilinear)",
        TextureFilter::Point => "nearest texel of the full-size images (--texture-filter point)",
    };
    let texture_plan = TexturePlan {
        enabled: textured_materials > 0,
        textured_materials,
        textures,
        bytes,
        filter,
        reason: if textured_materials > 0 {
            format!(
                "{textured_materials} materials with albedo maps, {textures} textures \
                 ({:.1} MiB of mip levels): {how}",
                bytes as f64 / (1u64 << 20) as f64
            )
        } else if mats.iter().any(|m| m.albedo_map.is_some()) {
            "the mapped materials have black albedo".into()
        } else {
            "no material has an albedo map".into()
        },
        read,
    };
    let alpha_plan = AlphaPlan {
        enabled: alpha_on,
        cutout_materials,
        blend_materials,
        reason: if alpha_on {
            format!(
                "{cutout_materials} cut-out materials (holes for every ray), {blend_materials} \
                 blended materials (rays continue behind them, shadows pass a share)"
            )
        } else if mats.iter().any(|m| m.uses_alpha()) {
            "the cut-out and blended materials are opaque at every texel".into()
        } else {
            "every material is opaque".into()
        },
        min_alpha,
    };
    (texture_plan, alpha_plan)
}

/// The culling and shadow-casting rules the soup's used materials and objects call for.
fn draw_rules(soup: &Soup, used: &[bool], lights: &[LightPlan]) -> (CullPlan, ShadowCastPlan) {
    let mut used_obj = vec![false; soup.objects.len()];
    // Materials whose culled faces matter to shadows: used on an object casting "on".
    let mut shadow_culled = vec![false; soup.materials.len()];
    for (&m, &o) in soup.tri_material.iter().zip(&soup.tri_object) {
        let (Some(obj), Some(mat)) = (soup.objects.get(o as usize), soup.materials.get(m as usize))
        else {
            continue;
        };
        used_obj[o as usize] = true;
        if mat.cull != Cull::None
            && matches!(obj.cast_shadows, CastShadows::On | CastShadows::ShadowsOnly)
        {
            shadow_culled[m as usize] = true;
        }
    }
    let used_mats = || {
        soup.materials
            .iter()
            .zip(used)
            .filter(|(_, &u)| u)
            .map(|(m, _)| m)
    };
    let culling_materials = used_mats().filter(|m| m.cull != Cull::None).count();
    let front = used_mats().filter(|m| m.cull == Cull::Front).count();
    let objs = || {
        soup.objects
            .iter()
            .zip(&used_obj)
            .filter(|(_, &u)| u)
            .map(|(o, _)| o)
    };
    let shadows_only = objs()
        .filter(|o| o.cast_shadows == CastShadows::ShadowsOnly)
        .count();
    let mut why = Vec::new();
    if culling_materials > 0 {
        why.push(if front > 0 {
            format!("back-face culling: {culling_materials} materials ({front} cull front faces)")
        } else {
            format!("back-face culling: {culling_materials} materials")
        });
    }
    if shadows_only > 0 {
        why.push(format!("{shadows_only} shadows-only objects"));
    }
    let culling = CullPlan {
        enabled: !why.is_empty(),
        culling_materials,
        shadows_only,
        reason: if why.is_empty() {
            "every material is two-sided and every object visible".into()
        } else {
            format!(
                "{}: camera and reflection rays continue past them",
                why.join(", ")
            )
        },
    };

    let non_casting = objs()
        .filter(|o| o.cast_shadows == CastShadows::Off)
        .count();
    let culled_in_shadow_pass = shadow_culled.iter().filter(|&&c| c).count();
    let unlit_materials = used_mats().filter(|m| m.unlit).count();
    let not_receiving = objs().filter(|o| !o.receive_shadows).count();
    let shadows = lights.iter().any(|l| l.enabled && l.shadow_rays > 0);
    let filter = non_casting + culled_in_shadow_pass + unlit_materials > 0;
    let shadow_casting = ShadowCastPlan {
        enabled: shadows && filter,
        non_casting,
        culled_in_shadow_pass,
        unlit_materials,
        not_receiving,
        reason: if !shadows {
            "no light traces shadow rays".into()
        } else if !filter {
            "every object casts from both faces: shadow rays stop at the first blocker".into()
        } else {
            format!(
                "{non_casting} objects cast no shadow, {culled_in_shadow_pass} materials cull \
                 faces in the shadow pass{}: shadow rays pass through them inside the traversal",
                if unlit_materials > 0 {
                    format!(", {unlit_materials} unlit materials cast none")
                } else {
                    String::new()
                }
            )
        } + &if not_receiving > 0 {
            format!("; {not_receiving} objects receive no shadows")
        } else {
            String::new()
        },
    };
    (culling, shadow_casting)
}

fn is_square(n: u32) -> bool {
    let k = (n as f64).sqrt().round() as u32;
    k * k == n
}

/// Where a soft light's samples are probed at its rim first (`soft::probe_fits`): a
/// clause for the plan's reason, empty where they never are.
fn rim_probe(l: &formats::Light, opts: &RenderOptions) -> String {
    if !crate::soft::probe_asked(opts) {
        return String::new();
    }
    match l.kind {
        LightKind::Directional if crate::soft::probe_fits(l, f32::INFINITY) => {
            ", where 4 probes of its rim disagree".into()
        }
        LightKind::Directional => String::new(),
        LightKind::Point | LightKind::Spot { .. } => format!(
            ", where 4 probes of its rim disagree at points {:.2} m away or more",
            crate::soft::probe_distance(l)
        ),
    }
}

/// How far from the camera the pipeline draws shadows, where it limits them.
fn shadow_reach(soup: &Soup) -> Option<String> {
    let d = soup.environment.shadow_distance?;
    let far = d.far(&soup.camera);
    Some(if d.border < 1e-4 {
        format!("; none beyond {far} m from the camera (the pipeline's shadow distance)")
    } else {
        format!(
            "; fading out from {} m to {far} m from the camera (the pipeline's shadow distance)",
            (1.0 - d.border) * far
        )
    })
}

fn light_plan(l: &formats::Light, shown: bool, opts: &RenderOptions) -> LightPlan {
    // A point or spot light names the pipeline whose falloff it follows when it is not
    // the built-in one.
    let kind = match (l.kind, l.attenuation) {
        (LightKind::Point, Attenuation::BuiltIn) => "point",
        (LightKind::Point, Attenuation::Universal) => "point, URP falloff",
        (LightKind::Spot { .. }, Attenuation::BuiltIn) => "spot",
        (LightKind::Spot { .. }, Attenuation::Universal) => "spot, URP falloff",
        (LightKind::Directional, _) => "directional",
    };
    let power = l.color * l.intensity;
    let off = |reason: String| LightPlan {
        name: l.name.clone(),
        kind,
        enabled: false,
        shadows: ShadowMode::None,
        shadow_rays: 0,
        reason,
    };
    if !power.is_finite() {
        return off("its colour or intensity is not a finite number".into());
    }
    if power.max_element() <= 0.0 {
        return off("black or zero intensity".into());
    }
    match l.kind {
        LightKind::Point | LightKind::Spot { .. } if l.range.is_nan() || l.range <= 0.0 => {
            return off(format!("range {} lights nothing", l.range))
        }
        LightKind::Spot { angle, .. } if angle.is_nan() || angle <= 0.0 => {
            return off(format!("spot angle {angle}° lights nothing"))
        }
        _ => {}
    }
    if !shown {
        return off("no material shows light (each is unlit, or black and fully metallic)".into());
    }
    let (shadows, shadow_rays, reason) = match l.shadows {
        Shadows::None => (ShadowMode::None, 0, "m_Shadows is none".to_string()),
        Shadows::Hard | Shadows::Soft if l.shadow_strength <= 0.0 => (
            ShadowMode::None,
            0,
            "shadow strength 0: its shadows take no light away".to_string(),
        ),
        Shadows::Hard => (ShadowMode::Hard, 1, "hard shadows".to_string()),
        Shadows::Soft if l.shadow_radius.is_nan() || l.shadow_radius <= 0.0 => (
            ShadowMode::Hard,
            1,
            format!(
                "soft shadows with a shadow radius of {}: a point emitter, traced as hard",
                l.shadow_radius
            ),
        ),
        Shadows::Soft if opts.soft_samples == 1 => (
            ShadowMode::Hard,
            1,
            "soft shadows with --soft-samples 1: traced as hard".to_string(),
        ),
        Shadows::Soft => (
            ShadowMode::Soft,
            opts.soft_samples,
            format!(
                "soft shadows: {} samples over a {}{}",
                opts.soft_samples,
                if matches!(l.kind, LightKind::Directional) {
                    format!("{}° cone", l.shadow_radius)
                } else {
                    format!("disc of radius {} m", l.shadow_radius)
                },
                rim_probe(l, opts)
            ),
        ),
    };
    let reason = if shadows != ShadowMode::None && l.shadow_strength < 1.0 {
        format!(
            "{reason}, at strength {} (they take that share of the light away)",
            l.shadow_strength
        )
    } else {
        reason
    };
    let reason = if l.culling_mask == u32::MAX {
        reason
    } else {
        format!("{reason}; lights layers {:#010x} only", l.culling_mask)
    };
    LightPlan {
        name: l.name.clone(),
        kind,
        enabled: true,
        shadows,
        shadow_rays,
        reason,
    }
}
