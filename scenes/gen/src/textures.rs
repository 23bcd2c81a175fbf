//! The `textures` project: one scene per way a material uses its albedo texture, alpha,
//! normal map and emission map, each a Quad seen square-on so every pixel's expected value follows from a texel.
//!
//! All scenes are lit by one white directional light of intensity 1 shining straight at
//! the Quads' fronts (Unity +Z) and have no ambient light, so a lit Quad's pixel is its
//! texel's linear value times its tint. The orthographic scenes see exactly the 1×1 Quad
//! at the origin when rendered square.

use crate::effects::Builder;
use crate::material::{MatDesc, Mode, Surface, TexSlot};
use crate::meta::TextureImport;
use crate::project::Project;
use crate::unity::{self, Ambient, CameraDesc, LightDesc, LightType, Xform};
use image::{ImageFormat, Rgba, RgbaImage};
use std::io::Cursor;

/// The quadrant texture's colours as the image file lists them (top row first):
/// top-left, top-right, bottom-left, bottom-right.
pub const QUADRANTS: [[u8; 4]; 4] = [
    [255, 0, 0, 255],
    [0, 255, 0, 255],
    [0, 0, 255, 255],
    [255, 255, 255, 255],
];

/// The grey texture's sRGB code (linear 0.2158).
pub const GREY: u8 = 128;

/// The cut-out texture's colour; its left column has alpha 0, its right alpha 255.
pub const CUTOUT_RGB: [u8; 3] = [255, 200, 0];

const NO_AMBIENT: Ambient = Ambient::Flat([0.0, 0.0, 0.0]);

/// A PNG of `w`×`h` texels given top row first.
pub fn png(w: u32, h: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let mut img = RgbaImage::new(w, h);
    for (i, t) in texels.iter().enumerate() {
        img.put_pixel(i as u32 % w, i as u32 / w, Rgba(*t));
    }
    let mut out = Cursor::new(Vec::new());
    img.write_to(&mut out, ImageFormat::Png)
        .expect("encoding a PNG in memory");
    out.into_inner()
}

/// Point filter, no mip maps: each pixel of a square render is one texel exactly.
const CRISP: TextureImport = TextureImport {
    filter: 0,
    mipmaps: false,
    srgb: true,
    wrap: 0,
    alpha_is_transparency: false,
    normal_map: false,
};

/// The normal map's texel: red 204 is a tilt of 0.6 towards increasing u (2·204/255 − 1),
/// green 128 one of 1/255 towards increasing v; blue is not read.
pub const BENT: [u8; 4] = [204, 128, 255, 255];

/// A white matte look. The texture scenes' looks have Specular Highlights off, as the
/// inspector turns them off, so each pixel is its texel's diffuse light alone.
fn white(name: &'static str) -> MatDesc {
    MatDesc {
        glossiness: 0.0,
        highlights: false,
        ..MatDesc::matte(name, [1.0, 1.0, 1.0])
    }
}

fn sun() -> LightDesc {
    LightDesc {
        kind: LightType::Directional,
        ..LightDesc::point([1.0, 1.0, 1.0], 1.0, 10.0)
    }
}

fn ortho() -> CameraDesc {
    CameraDesc {
        orthographic: Some(0.5),
        background: [0.0, 0.0, 0.0],
        ..CameraDesc::default()
    }
}

pub fn project() -> Project {
    let mut b = Builder::new(
        "textures",
        &[MatDesc {
            glossiness: 0.0,
            highlights: false,
            ..MatDesc::matte("Wall", [0.75, 0.75, 0.75])
        }],
    );
    // Every pixel follows from a texel and the sun alone.
    b.reflection(0.0);
    let quadrants = b.texture(
        "Assets/Textures/Quadrants.png",
        png(2, 2, &QUADRANTS),
        &CRISP,
    );
    let grey = b.texture(
        "Assets/Textures/Grey.png",
        png(4, 4, &[[GREY, GREY, GREY, 255]; 16]),
        &TextureImport {
            filter: 1,
            mipmaps: true,
            ..CRISP
        },
    );
    let [r, g, bl] = CUTOUT_RGB;
    let cutout = b.texture(
        "Assets/Textures/HalfCut.png",
        png(
            2,
            2,
            &[
                [r, g, bl, 0],
                [r, g, bl, 255],
                [r, g, bl, 0],
                [r, g, bl, 255],
            ],
        ),
        &TextureImport {
            alpha_is_transparency: true,
            ..CRISP
        },
    );
    let bent = b.texture(
        "Assets/Textures/Bent.png",
        png(2, 2, &[BENT; 4]),
        &TextureImport {
            srgb: false,
            normal_map: true,
            ..CRISP
        },
    );
    let textured = |guid: &str| Surface {
        main_tex: Some(TexSlot::new(guid)),
        ..Surface::default()
    };
    b.look(&white("Quadrants"), &textured(&quadrants));
    b.look(&white("Grey"), &textured(&grey));
    b.look(
        &white("Tiled"),
        &Surface {
            main_tex: Some(TexSlot {
                scale: [2.0, 1.0],
                offset: [0.5, 0.0],
                ..TexSlot::new(&quadrants)
            }),
            ..Surface::default()
        },
    );
    b.look(
        &white("Cutout"),
        &Surface {
            mode: Mode::Cutout,
            cutoff: 0.5,
            ..textured(&cutout)
        },
    );
    b.look(
        &MatDesc {
            emission: Some([1.0, 1.0, 1.0]),
            ..white("Glow")
        },
        &Surface {
            emission_map: Some(quadrants.clone()),
            ..Surface::default()
        },
    );
    b.look(
        &white("Bent"),
        &Surface {
            bump_map: Some((bent, 1.0)),
            ..Surface::default()
        },
    );
    b.look(
        &MatDesc {
            glossiness: 0.0,
            highlights: false,
            ..MatDesc::matte("HalfRed", [1.0, 0.0, 0.0])
        },
        &Surface {
            mode: Mode::Transparent,
            alpha: 0.5,
            ..Surface::default()
        },
    );

    // (a) The quadrant texture upright, filling a square view: red top-left, green
    // top-right, blue bottom-left, white bottom-right.
    square_on(&mut b, "Quadrants").scene("Quadrants", NO_AMBIENT);
    // (b) Uniform sRGB 128: every pixel is 0.2158 linear.
    square_on(&mut b, "Grey").scene("Grey", NO_AMBIENT);
    // (c) uv' = (2u + 0.5, v), repeating: the columns show the texture's right, left,
    // right and left halves.
    square_on(&mut b, "Tiled").scene("Tiling", NO_AMBIENT);
    // (d) A cut-out Quad whose left half is a hole, 1 m in front of a wall; the sun comes
    // from the front left, so the right half's shadow falls on the wall to its right.
    before_wall(&mut b)
        .mesh("Cutout", unity::QUAD, "Cutout", Xform::at(0.0, 0.0, 0.0))
        .light(
            "Sun",
            Xform::at(0.0, 3.0, -3.0).euler(0.0, 25.0, 0.0),
            sun(),
        )
        .scene("Cutout", NO_AMBIENT);
    // (e) A red Quad of tint alpha 0.5 (Transparent mode) in front of the wall.
    before_wall(&mut b)
        .mesh("Glass", unity::QUAD, "HalfRed", Xform::at(0.0, 0.0, 0.0))
        .light("Sun", Xform::at(0.0, 3.0, -3.0), sun())
        .scene("Transparent", NO_AMBIENT);
    // (f) A white Quad whose normal map tilts every normal towards increasing u (Unity
    // +X, the image's right), under a sun from the front right (30° off the Quad's
    // normal): lit at cos = 0.5·0.6 + cos 30°·0.8 ≈ 0.993, where a flat Quad takes
    // 0.866 and a mirrored map 0.393.
    b.camera(Xform::at(0.0, 0.0, -2.0), ortho())
        .mesh("Bent", unity::QUAD, "Bent", Xform::at(0.0, 0.0, 0.0))
        .light(
            "Sun",
            Xform::at(3.0, 0.0, -3.0).euler(0.0, -30.0, 0.0),
            sun(),
        )
        .scene("NormalMap", NO_AMBIENT);
    // (g) The quadrant texture as the emission map of a white glow, no light and no
    // ambient: the Quad shows the texture's colours by emission alone, upright.
    b.camera(Xform::at(0.0, 0.0, -2.0), ortho())
        .mesh("Glow", unity::QUAD, "Glow", Xform::at(0.0, 0.0, 0.0))
        .scene("EmissionMap", NO_AMBIENT);
    b.done()
}

/// A perspective camera 3 m in front of a 6 m wall (a Quad 1 m behind the origin).
fn before_wall(b: &mut Builder) -> &mut Builder {
    b.camera(Xform::at(0.0, 0.0, -3.0), CameraDesc::default())
        .mesh(
            "Wall",
            unity::QUAD,
            "Wall",
            Xform::at(0.0, 0.0, 1.0).uniform(6.0),
        )
}

/// A camera 2 m in front of a 1×1 Quad drawn with `look`, lit square-on.
fn square_on<'b>(b: &'b mut Builder, look: &str) -> &'b mut Builder {
    b.camera(Xform::at(0.0, 0.0, -2.0), ortho())
        .mesh(look, unity::QUAD, look, Xform::at(0.0, 0.0, 0.0))
        .light("Sun", Xform::at(0.0, 3.0, -3.0), sun())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(p: &Project, path: &str) -> String {
        String::from_utf8(p.files[path].clone()).unwrap()
    }

    #[test]
    fn materials_and_metas_say_what_the_inspector_would() {
        let p = project();
        let cut = text(&p, "Assets/Materials/Cutout.mat");
        assert!(cut.contains("  m_ValidKeywords:\n  - _ALPHATEST_ON\n"));
        assert!(cut.contains("  m_CustomRenderQueue: 2450\n"));
        assert!(cut.contains("    - _Mode: 1\n") && cut.contains("    - _Cutoff: 0.5\n"));
        let guid = p.guid("Assets/Textures/HalfCut.png");
        assert!(cut.contains(&format!(
            "    - _MainTex:\n        m_Texture: {{fileID: 2800000, guid: {guid}, type: 3}}\n"
        )));
        let tiled = text(&p, "Assets/Materials/Tiled.mat");
        assert!(tiled.contains("        m_Scale: {x: 2, y: 1}\n        m_Offset: {x: 0.5, y: 0}\n"));
        let glass = text(&p, "Assets/Materials/HalfRed.mat");
        assert!(glass.contains("    - _Mode: 3\n") && glass.contains("    - _ZWrite: 0\n"));
        assert!(glass.contains("    - _Color: {r: 1, g: 0, b: 0, a: 0.5}\n"));
        let meta = text(&p, "Assets/Textures/Quadrants.png.meta");
        assert!(meta.contains("    enableMipMap: 0\n") && meta.contains("    filterMode: 0\n"));
        let scenes = p.files.keys().filter(|k| k.ends_with(".unity")).count();
        assert_eq!(scenes, 7);
        let glow = text(&p, "Assets/Materials/Glow.mat");
        let quadrants = p.guid("Assets/Textures/Quadrants.png");
        assert!(glow.contains("  m_ValidKeywords:\n  - _EMISSION\n"));
        assert!(glow.contains(&format!(
            "    - _EmissionMap:\n        m_Texture: {{fileID: 2800000, guid: {quadrants}, type: 3}}\n"
        )));
        let bent = text(&p, "Assets/Materials/Bent.mat");
        assert!(bent.contains("  m_ValidKeywords:\n  - _NORMALMAP\n"));
        let guid = p.guid("Assets/Textures/Bent.png");
        assert!(bent.contains(&format!(
            "    - _BumpMap:\n        m_Texture: {{fileID: 2800000, guid: {guid}, type: 3}}\n"
        )));
        let meta = text(&p, "Assets/Textures/Bent.png.meta");
        assert!(meta.contains("    sRGBTexture: 0\n") && meta.contains("  textureType: 1\n"));
        // Top row first in the file: red at the top-left.
        let img = image::load_from_memory(&p.files["Assets/Textures/Quadrants.png"])
            .unwrap()
            .to_rgba8();
        assert_eq!(img.get_pixel(0, 0).0, QUADRANTS[0]);
        assert_eq!(img.get_pixel(1, 1).0, QUADRANTS[3]);
    }
}
