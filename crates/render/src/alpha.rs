//! What a material's alpha means to rays, resolved once per render from its mode, its
//! tint's opacity and its map's alpha channel.
//!
//! α at a hit is `opacity · texel alpha` (the map's alpha; 1 without a map).
//! * Cut-out: where α < cutoff the surface is a hole for camera, reflection and shadow
//!   rays, tested inside the traversal (a refused hit, no new query).
//! * Blend (Transparent/Fade): camera and reflection rays see α·L(surface) + (1 − α)·L(behind),
//!   the second term a continuation of the same ray past the hit; a shadow ray carries
//!   (1 − α) of the light past each blended surface it meets.
//!
//! A material whose α can never make a hole (cut-out) or let light through (blend) is
//! opaque to rays, so it costs no alpha lookup.

use formats::{Alpha, Material, Texture};

/// How rays treat a material's alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaUse {
    Opaque,
    Cutout { cutoff: f32 },
    Blend,
}

/// The smallest α a material can show: its opacity times the least alpha of its map.
/// `min_alpha` holds each soup texture's least texel alpha.
pub fn least_alpha(m: &Material, min_alpha: &[f32]) -> f32 {
    let map = m
        .albedo_map
        .and_then(|r| min_alpha.get(r.texture as usize).copied())
        .unwrap_or(1.0);
    m.opacity * map
}

/// How rays must treat `m`'s alpha (see the module notes).
pub fn alpha_use(m: &Material, min_alpha: &[f32]) -> AlphaUse {
    match m.alpha {
        Alpha::Opaque => AlphaUse::Opaque,
        Alpha::Cutout { cutoff } if least_alpha(m, min_alpha) < cutoff => {
            AlphaUse::Cutout { cutoff }
        }
        Alpha::Blend if least_alpha(m, min_alpha) < 1.0 => AlphaUse::Blend,
        Alpha::Cutout { .. } | Alpha::Blend => AlphaUse::Opaque,
    }
}

/// Each texture's least texel alpha, the input of [`alpha_use`].
pub fn min_alphas(textures: &[Texture]) -> Vec<f32> {
    textures.iter().map(crate::texture::min_alpha).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use formats::texture::{Filter, TextureRef, Tiling, Wrap};

    fn mat(alpha: Alpha, opacity: f32, map: bool) -> Material {
        Material {
            alpha,
            opacity,
            normal_map: None,
            emission_map: None,
            occlusion_map: None,
            metallic_map: None,
            unlit: false,
            albedo_map: map.then_some(TextureRef {
                texture: 0,
                tiling: Tiling::default(),
            }),
            ..Material::unity_default()
        }
    }

    #[test]
    fn only_alpha_that_can_show_is_used() {
        let t = Texture {
            source: "t".into(),
            width: 2,
            height: 1,
            texels: vec![9, 9, 9, 255, 9, 9, 9, 64],
            srgb: true,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            filter: Filter::Bilinear,
            mipmaps: false,
        };
        let min = min_alphas(&[t]);
        let cut = |c| Alpha::Cutout { cutoff: c };
        assert_eq!(
            alpha_use(&mat(cut(0.5), 1.0, true), &min),
            AlphaUse::Cutout { cutoff: 0.5 }
        );
        // No texel goes below 64/255.
        assert_eq!(alpha_use(&mat(cut(0.2), 1.0, true), &min), AlphaUse::Opaque);
        assert_eq!(
            alpha_use(&mat(cut(0.5), 1.0, false), &min),
            AlphaUse::Opaque
        );
        assert_eq!(
            alpha_use(&mat(cut(0.5), 0.4, false), &min),
            AlphaUse::Cutout { cutoff: 0.5 }
        );
        assert_eq!(
            alpha_use(&mat(Alpha::Blend, 1.0, false), &min),
            AlphaUse::Opaque
        );
        assert_eq!(
            alpha_use(&mat(Alpha::Blend, 1.0, true), &min),
            AlphaUse::Blend
        );
        assert_eq!(
            alpha_use(&mat(Alpha::Blend, 0.5, false), &min),
            AlphaUse::Blend
        );
        assert_eq!(
            alpha_use(&mat(Alpha::Opaque, 0.0, true), &min),
            AlphaUse::Opaque
        );
    }
}
