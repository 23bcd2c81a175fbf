//! RenderSettings' skybox material, when the renderer can draw it: Unity's procedural sky
//! (the built-in Default-Skybox, or a project material on the Skybox/Procedural shader)
//! and the sun it shows, or a sky from images (Skybox/Panoramic, Skybox/Cubemap, Skybox/6
//! Sided).

use crate::emit::Emitter;
use crate::material::{gamma_to_linear, keyword_on, linear_rgb, prop, props, shaded_rgb};
use crate::project::{ext, Project};
use crate::reference::fref;
use crate::settings::Pipeline;
use crate::texture::{load_linear, named_slot, Import, LinearImage};
use crate::yaml::Node;
use formats::{
    ColorSpace, Light, LightKind, Panorama, ProceduralSky, Sky, SkyImage, SkyLayout, SunDisk,
    TexturedSky,
};
use glam::{Vec3, Vec4};
use std::path::{Path, PathBuf};

/// Unity's built-in extra resources, where Default-Skybox and the skybox shaders live.
const BUILTIN_EXTRA: &str = "0000000000000000f000000000000000";
const DEFAULT_SKYBOX: i64 = 10304;
const PROCEDURAL_SHADER: i64 = 106;
const CUBEMAP_SHADER: i64 = 103;
const SIX_SIDED_SHADER: i64 = 104;
const PANORAMIC_SHADER: i64 = 108;
/// `unity_ColorSpaceDouble` in a linear-space project: the image shaders' factor on
/// `_Tint`, so that the default grey tint (0.5, linear 0.214) leaves texels at 0.98.
const COLOUR_SPACE_DOUBLE: f32 = 4.594_794;
/// The six-sided shader's face properties in [`SkyLayout::Cube`]'s order (+X is "Left").
const SIX_FACES: [&str; 6] = [
    "_LeftTex",
    "_RightTex",
    "_UpTex",
    "_DownTex",
    "_FrontTex",
    "_BackTex",
];

/// The Skybox/Procedural shader's default sky tint and ground colour, as stored.
const DEFAULT_TINT: Vec4 = Vec4::new(0.5, 0.5, 0.5, 1.0);
const DEFAULT_GROUND: Vec4 = Vec4::new(0.369, 0.349, 0.341, 1.0);

/// The Skybox/Procedural shader's property defaults, which Default-Skybox keeps.
fn default_sky() -> ProceduralSky {
    ProceduralSky {
        sun_disk: SunDisk::HighQuality,
        sun_size: 0.04,
        sun_size_convergence: 5.0,
        atmosphere_thickness: 1.0,
        exposure: 1.3,
        sky_tint: linear_rgb(DEFAULT_TINT),
        ground: linear_rgb(DEFAULT_GROUND),
        sun_direction: Vec3::Z,
        sun_colour: Vec3::ZERO,
    }
}

/// A procedural sky's tint and ground colour as a gamma-space project's shader takes them,
/// from the stored colours (`tint`, `ground`; the defaults where the material has none).
/// The soup keeps a linear project's values: the renderer raises the tint to 1/2.2 and uses
/// the ground as it is, where Unity's gamma-space shader uses the stored tint and squares
/// the stored ground colour (its `COLOR_2_GAMMA` and `COLOR_2_LINEAR`); so the tint is
/// kept as stored^2.2 and the ground as stored².
fn in_gamma_space(sky: &mut ProceduralSky, tint: Option<Vec4>, ground: Option<Vec4>) {
    let tint = tint.unwrap_or(DEFAULT_TINT).truncate();
    let ground = ground.unwrap_or(DEFAULT_GROUND).truncate();
    sky.sky_tint = tint.powf(2.2);
    sky.ground = ground * ground;
}

/// The sky RenderSettings names (a procedural sky's sun still unset), `Ok(None)` without
/// a skybox material, `Err` with the reason it cannot be drawn; what it draws otherwise
/// than Unity goes to `warnings`.
pub fn skybox(
    rs: &Node,
    project: &Project,
    warnings: &mut Vec<String>,
) -> Result<Option<Sky>, String> {
    let r = fref(rs.get("m_SkyboxMaterial"));
    let (id, guid) = (r.0, r.1.unwrap_or_default());
    if id == 0 {
        return Ok(None);
    }
    if project.settings.pipeline == Pipeline::HighDefinition {
        return Err("HDRP ignores RenderSettings' skybox (its sky is a Volume override)".into());
    }
    if guid == BUILTIN_EXTRA && id == DEFAULT_SKYBOX {
        let mut sky = default_sky();
        if project.settings.color_space == ColorSpace::Gamma {
            in_gamma_space(&mut sky, None, None);
        }
        return Ok(Some(Sky::Procedural(sky)));
    }
    let Some(path) = project.resolve(&guid) else {
        return Err(format!("skybox material GUID {guid} is not in the project"));
    };
    let body = match project.mat(path).as_ref() {
        Ok(Some(body)) => body.clone(),
        Ok(None) => return Err(format!("{} holds no Material", project.rel(path))),
        Err(e) => return Err(format!("{}: {e}", project.rel(path))),
    };
    let shader = fref(body.get("m_Shader"));
    let name = project.rel(path);
    if shader.1.as_deref() != Some(BUILTIN_EXTRA) {
        return Err(format!(
            "skybox {name} uses a project shader, not one of Unity's skybox shaders"
        ));
    }
    let layout = match shader.0 {
        PROCEDURAL_SHADER => {
            let sky = read_material(&body, project.settings.color_space);
            return Ok(Some(Sky::Procedural(sky)));
        }
        PANORAMIC_SHADER => panoramic(&body, project),
        CUBEMAP_SHADER => cubemap(&body, project),
        SIX_SIDED_SHADER => six_sided(&body, project, &name, warnings),
        other => {
            return Err(format!(
                "skybox {name} is not on a Skybox/Procedural, Panoramic, Cubemap or 6 Sided \
                 shader (shader fileID {other})"
            ))
        }
    }
    .map_err(|why| format!("skybox {name}: {why}"))?;
    let p = Props::of(&body);
    // `_Exposure` is a [Gamma] property: a linear-space project takes it decoded. Its
    // inspector keeps it within the shader's range, 0–8.
    let exposure = p.float("_Exposure").unwrap_or(1.0).clamp(0.0, 8.0);
    let space = project.settings.color_space;
    let tint = p
        .stored_colour("_Tint")
        .map(|c| shaded_rgb(c, space))
        .filter(|c| c.is_finite())
        .unwrap_or(shaded_rgb(Vec4::splat(0.5), space))
        .max(Vec3::ZERO);
    let scale = match space {
        ColorSpace::Linear => tint * COLOUR_SPACE_DOUBLE * gamma_to_linear(exposure),
        // A gamma-space project's `unity_ColorSpaceDouble` is 2, and its values stay as
        // stored.
        ColorSpace::Gamma => tint * 2.0 * exposure,
    };
    if !scale.is_finite() {
        return Err(format!(
            "skybox {name}: _Tint times _Exposure is too bright to draw"
        ));
    }
    Ok(Some(Sky::Textured(TexturedSky {
        scale,
        rotation: p.float("_Rotation").unwrap_or(0.0),
        layout,
    })))
}

/// A material's finite float and colour properties (colours linear). A number Unity
/// cannot have written (NaN, infinite) reads as absent, so the shader's default stands
/// and the soup stays one every reader takes.
struct Props<'a> {
    floats: Vec<(&'a str, &'a Node)>,
    colours: Vec<(&'a str, &'a Node)>,
}

impl<'a> Props<'a> {
    fn of(body: &'a Node) -> Self {
        let saved = body.get("m_SavedProperties");
        Props {
            floats: saved.map(|s| props(s, "m_Floats")).unwrap_or_default(),
            colours: saved.map(|s| props(s, "m_Colors")).unwrap_or_default(),
        }
    }

    fn float(&self, k: &str) -> Option<f32> {
        prop(&self.floats, k)
            .and_then(Node::as_f32)
            .filter(|x| x.is_finite())
    }

    fn colour(&self, k: &str) -> Option<Vec3> {
        self.stored_colour(k)
            .map(linear_rgb)
            .filter(|c| c.is_finite())
    }

    /// A colour as the file stores it (gamma-encoded), where it is finite.
    fn stored_colour(&self, k: &str) -> Option<Vec4> {
        prop(&self.colours, k)
            .and_then(Node::color)
            .filter(|c| c.is_finite())
    }
}

/// The file the texture slot `property` names, and its project-relative name.
fn texture_file(
    body: &Node,
    property: &str,
    project: &Project,
) -> Result<(PathBuf, String), String> {
    let slot = named_slot(body, property).ok_or_else(|| format!("{property} names no texture"))?;
    let path = project.resolve(&slot.guid).ok_or_else(|| {
        format!(
            "{property}: texture GUID {} is not in the project",
            slot.guid
        )
    })?;
    Ok((path.clone(), project.rel(path)))
}

/// The image at `path` (slot `property`, named `source`), linear; `resize` as
/// [`load_linear`].
fn load(
    path: &Path,
    source: &str,
    property: &str,
    import: &Import,
    resize: bool,
) -> Result<LinearImage, String> {
    if ext(path) == "cubemap" {
        return Err(format!(
            "{property}: {source} is a Unity .cubemap asset, which is not read (import the \
             cubemap from an image)"
        ));
    }
    load_linear(path, source, import, resize).map_err(|e| e.to_string())
}

/// The texture `property` names, linear, with its import settings; `resize` as
/// [`load_linear`].
fn image(
    body: &Node,
    property: &str,
    project: &Project,
    resize: bool,
) -> Result<(LinearImage, Import, String), String> {
    let (path, source) = texture_file(body, property, project)?;
    let mut import = Import::read(&path);
    // A gamma-space project's shaders take texels as stored.
    import.srgb &= project.settings.color_space == ColorSpace::Linear;
    let img = load(&path, &source, property, &import, resize)?;
    Ok((img, import, source))
}

fn sky_image(source: &str, img: &LinearImage) -> SkyImage {
    SkyImage::from_linear(source, img.width, img.height, &img.rgb)
}

/// Skybox/Panoramic: `_MainTex` in latitude-longitude (360° or 180°, one eye of a 3D
/// layout) or, with `_MAPPING_6_FRAMES_LAYOUT`, six faces in one image.
fn panoramic(body: &Node, project: &Project) -> Result<SkyLayout, String> {
    let p = Props::of(body);
    let six = match keyword_on(body, "_MAPPING_6_FRAMES_LAYOUT") {
        Some(on) => on,
        None => p.float("_Mapping") == Some(0.0),
    };
    if six {
        let (img, import, source) = image(body, "_MainTex", project, false)?;
        return cube_faces(&img, &import, &source);
    }
    let (mut img, _, source) = image(body, "_MainTex", project, true)?;
    // A camera that is not one eye of a stereo pair sees the left (or top) image.
    match p.float("_Layout").map(|l| l as i64) {
        Some(1) => img = crop(&img, 0, 0, (img.width / 2).max(1), img.height),
        Some(2) => {
            let half = (img.height / 2).max(1);
            img = crop(&img, 0, img.height - half, img.width, half);
        }
        _ => {}
    }
    let half = p.float("_ImageType") == Some(1.0);
    let mirrored = p.float("_MirrorOnBack").is_some_and(|m| m != 0.0);
    let panorama = match (half, mirrored) {
        (false, _) => Panorama::Full,
        (true, false) => Panorama::Half,
        (true, true) => Panorama::HalfMirrored,
    };
    Ok(SkyLayout::LatLong {
        image: sky_image(&source, &img),
        panorama,
    })
}

/// Skybox/Cubemap: `_Tex`, a texture imported as a cubemap from a latitude-longitude
/// image or six faces in one image (strip or cross).
fn cubemap(body: &Node, project: &Project) -> Result<SkyLayout, String> {
    let (path, source) = texture_file(body, "_Tex", project)?;
    let import = Import::read(&path);
    if !import.cube {
        return Err("_Tex is not imported as a cubemap (Texture Shape: Cube)".into());
    }
    if import.cube_mapping == 1 {
        return Err("_Tex is imported as a sphere map, which is not read".into());
    }
    // A cylindrical import is latitude-longitude at the import's size; automatic mapping
    // takes a 2:1 image so too, and six faces otherwise.
    let cylindrical = import.cube_mapping == 2;
    let img = load(&path, &source, "_Tex", &import, cylindrical)?;
    if cylindrical {
        return Ok(lat_long(&source, &img));
    }
    if import.cube_mapping != 5 && img.width == 2 * img.height {
        let (w, h) = import.imported_size(img.width, img.height);
        return Ok(lat_long(&source, &resized(&img, w, h)));
    }
    cube_faces(&img, &import, &source)
}

fn lat_long(source: &str, img: &LinearImage) -> SkyLayout {
    SkyLayout::LatLong {
        image: sky_image(source, img),
        panorama: Panorama::Full,
    }
}

/// Skybox/6 Sided: one 2D texture per face. A face without a texture shows the shader's
/// default grey (0.5), with a warning.
fn six_sided(
    body: &Node,
    project: &Project,
    name: &str,
    warnings: &mut Vec<String>,
) -> Result<SkyLayout, String> {
    let mut faces = Vec::with_capacity(6);
    for property in SIX_FACES {
        faces.push(match image(body, property, project, true) {
            Ok((img, _, source)) => sky_image(&source, &img),
            Err(why) => {
                warnings.push(format!("skybox {name}: {why}; that face is grey"));
                SkyImage::from_linear(property, 1, 1, &[Vec3::splat(0.5)])
            }
        });
    }
    Ok(SkyLayout::Cube { faces })
}

/// The six faces of one image laid out as Unity's cubemap import and the panoramic
/// shader's six-frame mapping read it, told apart by aspect: a horizontal strip (6:1, +X
/// −X +Y −Y +Z −Z), a horizontal cross (4:3), a vertical cross (3:4, −Z at the bottom,
/// upside down) or a vertical strip (1:6, +X at the top). Faces larger than the import's
/// maximum size are scaled down to it.
fn cube_faces(img: &LinearImage, import: &Import, source: &str) -> Result<SkyLayout, String> {
    let aspect = img.width as f32 / img.height as f32;
    // (columns, rows, each face's column and row counted from the bottom, −Z turned)
    let (cols, rows, cells, turned): (u32, u32, [(u32, u32); 6], bool) = if aspect > 1.0 {
        if aspect > (6.0 + 4.0 / 3.0) / 2.0 {
            (
                6,
                1,
                [(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (5, 0)],
                false,
            )
        } else {
            (
                4,
                3,
                [(2, 1), (0, 1), (1, 2), (1, 0), (1, 1), (3, 1)],
                false,
            )
        }
    } else if aspect > (1.0 / 6.0 + 3.0 / 4.0) / 2.0 {
        (3, 4, [(2, 2), (0, 2), (1, 3), (1, 1), (1, 2), (1, 0)], true)
    } else {
        (
            1,
            6,
            [(0, 5), (0, 4), (0, 3), (0, 2), (0, 1), (0, 0)],
            false,
        )
    };
    let (fw, fh) = (img.width / cols, img.height / rows);
    if fw == 0 || fh == 0 {
        return Err(format!(
            "{source}: {}x{} is too small for six faces",
            img.width, img.height
        ));
    }
    let faces = cells
        .iter()
        .enumerate()
        .map(|(f, &(c, r))| {
            let mut face = crop(img, c * fw, r * fh, fw, fh);
            if turned && f == 5 {
                face.rgb.reverse();
            }
            let side = import.max_size;
            if fw > side || fh > side {
                face = resized(&face, fw.min(side), fh.min(side));
            }
            SkyImage::from_linear(
                &format!("{source} face {f}"),
                face.width,
                face.height,
                &face.rgb,
            )
        })
        .collect();
    Ok(SkyLayout::Cube { faces })
}

/// The `w`×`h` block of `img` whose bottom-left texel is (x, y).
fn crop(img: &LinearImage, x: u32, y: u32, w: u32, h: u32) -> LinearImage {
    let rgb = (y..y + h)
        .flat_map(|row| {
            let start = (row * img.width + x) as usize;
            img.rgb[start..start + w as usize].iter().copied()
        })
        .collect();
    LinearImage {
        width: w,
        height: h,
        rgb,
    }
}

/// `img` resampled to `w`×`h` (a triangle filter, as the texture importer scales).
fn resized(img: &LinearImage, w: u32, h: u32) -> LinearImage {
    if (w, h) == (img.width, img.height) {
        return img.clone();
    }
    let flat: Vec<f32> = img.rgb.iter().flat_map(|c| c.to_array()).collect();
    let Some(buffer) = image::Rgb32FImage::from_raw(img.width, img.height, flat) else {
        return img.clone();
    };
    let out = image::imageops::resize(&buffer, w, h, image::imageops::FilterType::Triangle);
    LinearImage {
        width: w,
        height: h,
        rgb: out.pixels().map(|p| Vec3::from_array(p.0)).collect(),
    }
}

/// A Skybox/Procedural material's properties over the shader's defaults.
fn read_material(body: &Node, space: ColorSpace) -> ProceduralSky {
    let mut sky = default_sky();
    let p = Props::of(body);
    let float = |k: &str| p.float(k);
    let colour = |k: &str| p.colour(k);
    sky.sun_size = float("_SunSize").unwrap_or(sky.sun_size);
    sky.sun_size_convergence = float("_SunSizeConvergence").unwrap_or(sky.sun_size_convergence);
    sky.atmosphere_thickness = float("_AtmosphereThickness").unwrap_or(sky.atmosphere_thickness);
    sky.exposure = float("_Exposure").unwrap_or(sky.exposure);
    sky.sky_tint = colour("_SkyTint").unwrap_or(sky.sky_tint);
    sky.ground = colour("_GroundColor").unwrap_or(sky.ground);
    if space == ColorSpace::Gamma {
        let stored = |k: &str| p.stored_colour(k).filter(|c| c.truncate().is_finite());
        in_gamma_space(&mut sky, stored("_SkyTint"), stored("_GroundColor"));
    }
    // The keyword picks the shader variant; without one the float mirrors it.
    let on = |k: &str| keyword_on(body, k) == Some(true);
    sky.sun_disk = if on("_SUNDISK_NONE") {
        SunDisk::None
    } else if on("_SUNDISK_SIMPLE") {
        SunDisk::Simple
    } else if on("_SUNDISK_HIGH_QUALITY") {
        SunDisk::HighQuality
    } else {
        match float("_SunDisk").map(|f| f as i64) {
            Some(0) => SunDisk::None,
            Some(1) => SunDisk::Simple,
            _ => SunDisk::HighQuality,
        }
    };
    sky
}

/// Point the sky at its sun: the light RenderSettings names (`m_Sun`, `named`) when it
/// is a converted directional light, else the brightest directional light. Without one
/// the direction stays Unity's +Z and the colour black (no sun disk), as URP leaves its
/// main light.
pub fn aim(sky: &mut ProceduralSky, lights: &[Light], named: Option<usize>) {
    let directional = |l: &&Light| matches!(l.kind, LightKind::Directional);
    let brightness = |l: &Light| (l.color * l.intensity).element_sum();
    let sun = named
        .and_then(|i| lights.get(i))
        .filter(directional)
        .or_else(|| {
            lights
                .iter()
                .filter(directional)
                .max_by(|a, b| brightness(a).total_cmp(&brightness(b)))
        });
    if let Some(sun) = sun {
        sky.sun_direction = -sun.direction;
        sky.sun_colour = sun.color * sun.intensity;
    }
}

impl Emitter<'_, '_> {
    /// The procedural sky RenderSettings `rs` names, aimed at the scene's sun (the top
    /// scene's file is the graph's first).
    /// `seen`: a camera or the ambient light shows it; `reflected`: surfaces reflect it.
    pub(crate) fn sky(&mut self, rs: &Node, seen: bool, reflected: bool) {
        let mut warnings = Vec::new();
        let sky = skybox(rs, self.g.project, &mut warnings);
        for w in warnings {
            self.soup
                .warnings
                .push(format!("{}: RenderSettings: {w}", self.scene_rel));
        }
        match sky {
            Ok(Some(Sky::Procedural(mut sky))) => {
                let named = self.sun(rs);
                aim(&mut sky, &self.soup.lights, named);
                self.soup.environment.sky = Some(Sky::Procedural(sky));
            }
            Ok(Some(sky)) => self.soup.environment.sky = Some(sky),
            Ok(None) => {}
            Err(why) => self.soup.warnings.push(format!(
                "{}: RenderSettings: {why}; {}",
                self.scene_rel,
                match (seen, reflected) {
                    (true, false) => "a sky gradient stands in",
                    (true, true) => "a sky gradient stands in, and surfaces reflect no sky",
                    _ => "surfaces reflect no sky",
                }
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yaml::parse;

    #[test]
    fn a_procedural_material_overrides_the_defaults_it_names() {
        let m = parse(
            "Material:\n  m_Shader: {fileID: 106, guid: 0000000000000000f000000000000000, type: 0}\n  m_ShaderKeywords: _SUNDISK_SIMPLE\n  m_SavedProperties:\n    m_Floats:\n    - _AtmosphereThickness: 0.53\n    - _Exposure: 1.25\n    m_Colors:\n    - _SkyTint: {r: 1, g: 1, b: 1, a: 1}\n",
        );
        let sky = read_material(m.get("Material").unwrap(), ColorSpace::Linear);
        assert_eq!(sky.atmosphere_thickness, 0.53);
        assert_eq!(sky.exposure, 1.25);
        assert_eq!(sky.sky_tint, Vec3::ONE);
        assert_eq!(sky.sun_disk, SunDisk::Simple);
        assert_eq!(sky.sun_size, 0.04, "the shader's default");
        assert_eq!(sky.ground, default_sky().ground);
    }

    #[test]
    fn a_gamma_space_project_keeps_the_tint_as_stored_and_squares_the_ground() {
        let m = parse(
            "Material:\n  m_SavedProperties:\n    m_Colors:\n    - _SkyTint: {r: 0.6, g: 0.5, b: 0.4, a: 1}\n    - _GroundColor: {r: 0.3, g: 0.2, b: 0.1, a: 1}\n",
        );
        let sky = read_material(m.get("Material").unwrap(), ColorSpace::Gamma);
        // The renderer raises the tint to 1/2.2: Unity's gamma shader's stored tint.
        let seen = sky.sky_tint.powf(1.0 / 2.2);
        assert!(
            (seen - Vec3::new(0.6, 0.5, 0.4)).abs().max_element() < 1e-6,
            "{seen}"
        );
        assert!(
            (sky.ground - Vec3::new(0.09, 0.04, 0.01))
                .abs()
                .max_element()
                < 1e-6
        );
        // A material without them takes the shader's defaults, so converted.
        let bare = parse("Material:\n  m_SavedProperties:\n    m_Colors: []\n");
        let sky = read_material(bare.get("Material").unwrap(), ColorSpace::Gamma);
        assert!(
            (sky.sky_tint - Vec3::splat(0.5f32.powf(2.2)))
                .abs()
                .max_element()
                < 1e-6
        );
        assert!((sky.ground.x - 0.369 * 0.369).abs() < 1e-6);
        // A linear project decodes both from sRGB, as before.
        let sky = read_material(m.get("Material").unwrap(), ColorSpace::Linear);
        assert_eq!(sky.ground, linear_rgb(Vec4::new(0.3, 0.2, 0.1, 1.0)));
    }

    /// Every texel of a `w`×`h` image its own number, and the faces cut from it.
    fn faces_of(w: u32, h: u32) -> Vec<SkyImage> {
        let rgb = (0..w * h).map(|i| Vec3::splat(i as f32)).collect();
        let img = LinearImage {
            width: w,
            height: h,
            rgb,
        };
        match cube_faces(&img, &Import::default(), "x").unwrap() {
            SkyLayout::Cube { faces } => faces,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn six_faces_are_cut_from_strips_and_crosses() {
        // A horizontal strip of 2×2 faces, 12×2: face f starts at column 2f.
        let strip = faces_of(12, 2);
        for (f, face) in strip.iter().enumerate() {
            assert_eq!(face.texel(0, 0), Vec3::splat(2.0 * f as f32), "face {f}");
            assert_eq!(face.texel(1, 1), Vec3::splat(12.0 + 2.0 * f as f32 + 1.0));
        }
        // A vertical cross, 3×4 cells of one texel: +X at (2, 2), +Y at the top, −Z at the
        // bottom (one texel: its turn shows on larger faces below).
        let cross = faces_of(3, 4);
        let at = |c: u32, r: u32| Vec3::splat((r * 3 + c) as f32);
        let cells = [(2, 2), (0, 2), (1, 3), (1, 1), (1, 2), (1, 0)];
        for (face, (c, r)) in cross.iter().zip(cells) {
            assert_eq!(face.texel(0, 0), at(c, r));
        }
        // Its −Z face is upside down in the image: its bottom-left texel is the cell's
        // top-right (row 1, column 3 of the image).
        let cross = faces_of(6, 8);
        assert_eq!(cross[5].texel(0, 0), Vec3::splat(9.0));
        assert_eq!(cross[5].texel(1, 1), Vec3::splat(2.0));
        // A horizontal cross: −X at the left of the middle row, −Z at its right.
        let cross = faces_of(8, 6);
        assert_eq!(cross[1].texel(0, 0), Vec3::splat(16.0));
        assert_eq!(cross[5].texel(1, 1), Vec3::splat(3.0 * 8.0 + 7.0));
    }

    #[test]
    fn a_property_that_is_not_a_finite_number_keeps_the_default() {
        let m = parse(
            "Material:\n  m_SavedProperties:\n    m_Floats:\n    - _Exposure: NaN\n    - _SunSize: Infinity\n    m_Colors:\n    - _SkyTint: {r: NaN, g: 1, b: 1, a: 1}\n",
        );
        let sky = read_material(m.get("Material").unwrap(), ColorSpace::Linear);
        let default = default_sky();
        assert_eq!(
            (sky.exposure, sky.sun_size, sky.sky_tint),
            (default.exposure, default.sun_size, default.sky_tint)
        );
    }

    #[test]
    fn the_sun_is_the_named_light_or_the_brightest_directional_one() {
        let light = |kind, intensity: f32, direction: Vec3| Light {
            name: "l".into(),
            kind,
            position: Vec3::ZERO,
            direction,
            color: Vec3::ONE,
            intensity,
            range: 10.0,
            attenuation: formats::Attenuation::BuiltIn,
            shadows: formats::Shadows::None,
            shadow_radius: 0.0,
            shadow_strength: 1.0,
            culling_mask: u32::MAX,
        };
        let lights = [
            light(LightKind::Point, 9.0, Vec3::Y),
            light(LightKind::Directional, 1.0, -Vec3::Y),
            light(LightKind::Directional, 2.0, -Vec3::X),
        ];
        let mut sky = default_sky();
        aim(&mut sky, &lights, Some(1));
        assert_eq!((sky.sun_direction, sky.sun_colour), (Vec3::Y, Vec3::ONE));
        // A point light named as the sun does not count; the brightest directional does.
        aim(&mut sky, &lights, Some(0));
        assert_eq!(
            (sky.sun_direction, sky.sun_colour),
            (Vec3::X, Vec3::splat(2.0))
        );
        let mut dark = default_sky();
        aim(&mut dark, &lights[..1], None);
        assert_eq!((dark.sun_direction, dark.sun_colour), (Vec3::Z, Vec3::ZERO));
    }
}
