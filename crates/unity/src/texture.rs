//! Albedo, normal, emission, occlusion and metallic maps: which textures a `.mat` draws with, how their `.meta`
//! TextureImporter says to import them, and decoding the image file into a [`formats::texture::Texture`] the
//! way Unity's importer would hand it to the shader (power-of-two rounding, size limit,
//! bottom row first).

use crate::material::{prop, props};
use crate::project::{ext, Project};
use crate::yaml::{self, Node};
use formats::texture::{Filter, Texture, Tiling, Wrap, MAX_SIDE};
use image::{DynamicImage, ImageFormat, ImageReader, Limits};
use std::io::Cursor;
use std::path::Path;

/// Shader guids whose albedo property is known.
const URP_LIT: &str = "933532a4fcc9baf4fa0491de14d08ed7";
const HDRP_LIT: &str = "6e4ae4064600d784cac1e41a9e6f2e59";
const BUILTIN_SHADERS: &str = "0000000000000000f000000000000000";

/// Albedo properties in the order tried when the shader is not one of the above: URP
/// files keep a stale `_MainTex` beside `_BaseMap`, HDRP beside `_BaseColorMap`.
const ALBEDO_PROPERTIES: [&str; 3] = ["_BaseColorMap", "_BaseMap", "_MainTex"];

#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    #[error("{property}: texture guid {guid} is not in the project")]
    Unresolved { property: String, guid: String },
    #[error("{path}: cannot read texture: {message}")]
    Read { path: String, message: String },
    #[error("{path}: a Git LFS pointer, not the texture itself")]
    LfsPointer { path: String },
    #[error(
        "{path}: .{ext} textures are not supported (png, jpg, tga, tif, bmp, exr, hdr, psd are)"
    )]
    Unsupported { path: String, ext: String },
    #[error("{path}: not a readable {format} image: {message}")]
    Decode {
        path: String,
        format: String,
        message: String,
    },
    #[error("{path}: {width}x{height} texels, larger than {MAX_SIDE} on a side")]
    TooLarge {
        path: String,
        width: u32,
        height: u32,
    },
}

/// A texture slot of a material: which property, which texture, what tiling.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureSlot {
    pub property: String,
    pub guid: String,
    pub tiling: Tiling,
}

/// The albedo texture slot of a Material body, in either `m_TexEnvs` layout. `None` when
/// the material's albedo property is empty (`{fileID: 0}`) or absent.
pub fn albedo_slot(body: &Node) -> Option<TextureSlot> {
    if crate::material::unlit_shader(body).is_some_and(|u| !u.textured) {
        return None;
    }
    let envs = tex_envs(body)?;
    let slot = |name: &str| prop(&envs, name);
    // A known shader reads only its own property: an empty one means untextured even
    // when a stale slot from an earlier shader still names a texture.
    if let Some(name) = own_albedo(body) {
        if let Some(env) = slot(name) {
            return texture_of(name, env);
        }
    }
    ALBEDO_PROPERTIES
        .iter()
        .find_map(|name| slot(name).and_then(|env| texture_of(name, env)))
}

/// The albedo property of the material's shader, where it is one whose property is known.
fn own_albedo(body: &Node) -> Option<&'static str> {
    match body.get("m_Shader").and_then(|s| s.str_at("guid")) {
        Some(URP_LIT | crate::material::URP_UNLIT) => Some("_BaseMap"),
        Some(HDRP_LIT) => Some("_BaseColorMap"),
        Some(BUILTIN_SHADERS) => Some("_MainTex"),
        _ => None,
    }
}

/// The `m_TexEnvs` entries of a Material body, in either layout.
fn tex_envs(body: &Node) -> Option<Vec<(&str, &Node)>> {
    Some(props(body.get("m_SavedProperties")?, "m_TexEnvs"))
}

/// The normal map of a Material body and its scale, where the shader samples one: Standard
/// and URP Lit `_BumpMap` (`_BumpScale`), HDRP Lit `_NormalMap` (`_NormalScale`), only
/// with the `_NORMALMAP` keyword (or in a file that lists no keywords). Its UVs are tiled
/// by the albedo property's scale and offset, as Unity's shaders transform every map's UVs
/// by the main texture's, whether or not the albedo slot holds a texture.
pub fn normal_slot(body: &Node) -> Option<(TextureSlot, f32)> {
    if crate::material::keyword_on(body, "_NORMALMAP") == Some(false) {
        return None;
    }
    let shader = body.get("m_Shader").and_then(|s| s.str_at("guid"));
    let (texture, scale) = match shader {
        Some(HDRP_LIT) => ("_NormalMap", "_NormalScale"),
        _ => ("_BumpMap", "_BumpScale"),
    };
    let found = map_slot(body, texture)?;
    Some((found, finite_float(body, scale).unwrap_or(1.0)))
}

/// The emission map of a Material body (`_EmissionMap` of the Standard and URP Lit
/// shaders), tiled as the albedo map, as those shaders sample it with the main texture's
/// UVs. Whether it shows is the emission colour's and keyword's business
/// ([`crate::material::convert`]).
pub fn emission_slot(body: &Node) -> Option<TextureSlot> {
    map_slot(body, "_EmissionMap")
}

/// The occlusion map of a Material body and its strength (`_OcclusionMap`,
/// `_OcclusionStrength`, default 1, kept within 0–1), tiled as the albedo map. URP Lit
/// samples it only with the `_OCCLUSIONMAP` keyword (where the file lists keywords); the
/// Standard shader whenever the slot holds a texture. HDRP keeps occlusion in its mask
/// map, which is not read.
pub fn occlusion_slot(body: &Node) -> Option<(TextureSlot, f32)> {
    let shader = body.get("m_Shader").and_then(|s| s.str_at("guid"));
    match shader {
        Some(HDRP_LIT) => return None,
        Some(URP_LIT) if crate::material::keyword_on(body, "_OCCLUSIONMAP") == Some(false) => {
            return None
        }
        _ => {}
    }
    let found = map_slot(body, "_OcclusionMap")?;
    let strength = finite_float(body, "_OcclusionStrength").unwrap_or(1.0);
    Some((found, strength.clamp(0.0, 1.0)))
}

/// The metallic map of a Material body and the scale of its alpha (smoothness), where the
/// shader reads metallic and smoothness from one: Standard's `_MetallicGlossMap` with the
/// `_METALLICGLOSSMAP` keyword, scaled by `_GlossMapScale` (default 1), and URP Lit's in
/// its metallic workflow with `_METALLICSPECGLOSSMAP`, scaled by `_Smoothness` (default
/// 0.5); in a file that lists no keywords, whenever the slot holds a texture. Tiled as the
/// albedo map. The other built-in shaders read none (Standard (Specular setup)'s
/// `_SpecGlossMap` is a specular colour), nor does HDRP, which keeps metallic in its mask
/// map.
pub fn metallic_slot(body: &Node) -> Option<(TextureSlot, f32)> {
    let (keyword, scale, default) = match crate::material::shader_of(body) {
        (Some(BUILTIN_SHADERS), Some(crate::material::STANDARD)) => {
            ("_METALLICGLOSSMAP", "_GlossMapScale", 1.0)
        }
        (Some(BUILTIN_SHADERS) | Some(HDRP_LIT), _) => return None,
        (Some(URP_LIT), _) => {
            let specular = crate::material::keyword_on(body, "_SPECULAR_SETUP")
                .unwrap_or_else(|| finite_float(body, "_WorkflowMode") == Some(0.0));
            if specular {
                return None;
            }
            ("_METALLICSPECGLOSSMAP", "_Smoothness", 0.5)
        }
        _ => ("_METALLICGLOSSMAP", "_GlossMapScale", 1.0),
    };
    if crate::material::keyword_on(body, keyword) == Some(false) {
        return None;
    }
    let found = map_slot(body, "_MetallicGlossMap")?;
    let scale = finite_float(body, scale).unwrap_or(default);
    Some((found, scale.clamp(0.0, 1.0)))
}

/// The finite value of a Material body's float property `name`, where it has one.
fn finite_float(body: &Node, name: &str) -> Option<f32> {
    let floats = props(body.get("m_SavedProperties")?, "m_Floats");
    prop(&floats, name)
        .and_then(Node::as_f32)
        .filter(|x| x.is_finite())
}

/// The texture in slot `property`, tiled by the albedo property's scale and offset (the
/// shader's own albedo property, else the first present), as Unity's shaders tile every
/// map by the main texture's.
fn map_slot(body: &Node, property: &str) -> Option<TextureSlot> {
    let envs = tex_envs(body)?;
    let mut found = texture_of(property, prop(&envs, property)?)?;
    let main = prop(&envs, own_albedo(body).unwrap_or("_MainTex"))
        .or_else(|| ALBEDO_PROPERTIES.iter().find_map(|name| prop(&envs, name)));
    found.tiling = main.map_or_else(Tiling::default, tiling_of);
    Some(found)
}

/// The texture a material's `property` names, with that property's own tiling.
pub fn named_slot(body: &Node, property: &str) -> Option<TextureSlot> {
    texture_of(property, prop(&tex_envs(body)?, property)?)
}

fn texture_of(property: &str, env: &Node) -> Option<TextureSlot> {
    let tex = env.get("m_Texture")?;
    if tex.i64_at("fileID").unwrap_or(0) == 0 {
        return None;
    }
    let guid = tex.str_at("guid")?.trim().to_string();
    Some(TextureSlot {
        property: property.to_string(),
        guid,
        tiling: tiling_of(env),
    })
}

fn tiling_of(env: &Node) -> Tiling {
    let pair = |key: &str, default: f32| {
        let n = env.get(key);
        [
            n.and_then(|n| n.f32_at("x")).unwrap_or(default),
            n.and_then(|n| n.f32_at("y")).unwrap_or(default),
        ]
    };
    Tiling {
        scale: pair("m_Scale", 1.0),
        offset: pair("m_Offset", 0.0),
    }
}

/// TextureImporter `nPOTScale`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Npot {
    None,
    ToNearest,
    ToLarger,
    ToSmaller,
}

/// What a texture's `.meta` says about importing it.
#[derive(Clone, Debug, PartialEq)]
pub struct Import {
    pub srgb: bool,
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    pub filter: Filter,
    pub mipmaps: bool,
    pub max_size: u32,
    pub npot: Npot,
    /// The importer dilates colour into transparent texels; cut-out rendering will want it.
    pub alpha_is_transparency: bool,
    /// `bumpmap.convertToNormalMap`: Unity makes the normal map from the image's grey
    /// levels as heights, which this converter does not.
    pub from_grayscale: bool,
    /// `bumpmap.flipGreenChannel` on a normal map (`textureType: 1`): the image's green
    /// channel points along decreasing v (DirectX's convention) and is inverted on import.
    pub flip_green: bool,
    /// `textureShape: 2`: imported as a cubemap, laid out as `generateCubemap` says.
    pub cube: bool,
    /// `generateCubemap`: 1 sphere map, 2 cylindrical (latitude-longitude), 5 six faces,
    /// 6 (the default) chosen by the image's aspect.
    pub cube_mapping: i64,
}

impl Default for Import {
    fn default() -> Self {
        Import {
            srgb: true,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            filter: Filter::Bilinear,
            mipmaps: true,
            max_size: 2048,
            npot: Npot::ToNearest,
            alpha_is_transparency: false,
            from_grayscale: false,
            flip_green: false,
            cube: false,
            cube_mapping: 6,
        }
    }
}

/// Unity's wrap codes; −1 (unset) is repeat, and MirrorOnce (3) mirrors like Mirror.
fn wrap_mode(code: i64) -> Option<Wrap> {
    match code {
        0 => Some(Wrap::Repeat),
        1 => Some(Wrap::Clamp),
        2 | 3 => Some(Wrap::Mirror),
        _ => None,
    }
}

impl Import {
    /// The settings in `<texture>.meta`; Unity's defaults without one.
    pub fn read(texture: &Path) -> Import {
        let mut meta = texture.as_os_str().to_owned();
        meta.push(".meta");
        Import::parse(&std::fs::read_to_string(meta).unwrap_or_default())
    }

    pub fn parse(text: &str) -> Import {
        let mut im = Import::default();
        let root = yaml::parse(text);
        let Some(imp) = root.get("TextureImporter") else {
            return im;
        };
        let mips = imp.get("mipmaps");
        let at = |key: &str| mips.and_then(|m| m.i64_at(key)).or_else(|| imp.i64_at(key));
        if let Some(s) = at("sRGBTexture") {
            im.srgb = s == 1;
        } else if let Some(l) = at("linearTexture") {
            im.srgb = l != 1;
        }
        if let Some(m) = at("enableMipMap") {
            im.mipmaps = m != 0;
        }
        if let Some(ts) = imp.get("textureSettings") {
            if let Some(w) = ts.i64_at("wrapMode").and_then(wrap_mode) {
                (im.wrap_u, im.wrap_v) = (w, w);
            }
            if let Some(w) = ts.i64_at("wrapU").and_then(wrap_mode) {
                im.wrap_u = w;
            }
            if let Some(w) = ts.i64_at("wrapV").and_then(wrap_mode) {
                im.wrap_v = w;
            }
            im.filter = match ts.i64_at("filterMode") {
                Some(0) => Filter::Point,
                Some(2) => Filter::Trilinear,
                _ => Filter::Bilinear,
            };
        }
        // The default platform's entry is what the editor shows and uses; the top-level
        // key is the older home of the same setting.
        let platform = imp
            .get("platformSettings")
            .map(Node::as_seq)
            .unwrap_or(&[])
            .iter()
            .find(|p| {
                matches!(
                    p.str_at("buildTarget"),
                    Some("DefaultTexturePlatform") | Some("Default")
                )
            })
            .and_then(|p| p.i64_at("maxTextureSize"));
        if let Some(m) = platform.or_else(|| imp.i64_at("maxTextureSize")) {
            if m > 0 {
                im.max_size = m.min(MAX_SIDE as i64) as u32;
            }
        }
        im.npot = match imp.i64_at("nPOTScale") {
            Some(0) => Npot::None,
            Some(2) => Npot::ToLarger,
            Some(3) => Npot::ToSmaller,
            _ => Npot::ToNearest,
        };
        // Sprite (8) and legacy GUI (2) textures are never rescaled to powers of two.
        if matches!(imp.i64_at("textureType"), Some(2) | Some(8)) {
            im.npot = Npot::None;
        }
        im.alpha_is_transparency = imp.i64_at("alphaIsTransparency") == Some(1);
        let bumpmap = |key: &str| imp.get("bumpmap").and_then(|b| b.i64_at(key)) == Some(1);
        im.from_grayscale = bumpmap("convertToNormalMap");
        im.flip_green = bumpmap("flipGreenChannel") && imp.i64_at("textureType") == Some(1);
        im.cube = imp.i64_at("textureShape") == Some(2);
        im.cube_mapping = imp.i64_at("generateCubemap").unwrap_or(6);
        im
    }

    /// The size Unity imports a `w`×`h` image at: each side rounded to a power of two as
    /// `nPOTScale` says, then both scaled so the larger fits `maxTextureSize`.
    pub fn imported_size(&self, w: u32, h: u32) -> (u32, u32) {
        let (mut w, mut h) = (pot(w, self.npot), pot(h, self.npot));
        let largest = w.max(h);
        if largest > self.max_size {
            let f = self.max_size as f64 / largest as f64;
            w = ((w as f64 * f).round() as u32).max(1);
            h = ((h as f64 * f).round() as u32).max(1);
        }
        (w, h)
    }
}

fn pot(n: u32, mode: Npot) -> u32 {
    if n.is_power_of_two() || mode == Npot::None {
        return n;
    }
    let hi = n.next_power_of_two();
    let lo = hi / 2;
    match mode {
        Npot::ToLarger => hi,
        Npot::ToSmaller => lo,
        // Ties go up, as the larger texture loses nothing.
        _ if n - lo < hi - n => lo,
        _ => hi,
    }
}

/// A decoded albedo map with the material's tiling.
#[derive(Clone, Debug)]
pub struct Albedo {
    pub property: String,
    pub tiling: Tiling,
    pub import: Import,
    pub texture: Texture,
}

/// The albedo texture of a Material body, loaded: `Ok(None)` for an untextured material.
pub fn load_albedo(project: &Project, body: &Node) -> Result<Option<Albedo>, TextureError> {
    let Some(slot) = albedo_slot(body) else {
        return Ok(None);
    };
    let path = project
        .resolve(&slot.guid)
        .ok_or_else(|| TextureError::Unresolved {
            property: slot.property.clone(),
            guid: slot.guid.clone(),
        })?;
    let import = Import::read(path);
    let texture = load(path, &project.rel(path), &import)?;
    Ok(Some(Albedo {
        property: slot.property,
        tiling: slot.tiling,
        import,
        texture,
    }))
}

/// Decode the image at `path` (named `source` in the texture and in errors) and import it
/// as `import` says.
pub fn load(path: &Path, source: &str, import: &Import) -> Result<Texture, TextureError> {
    let bytes = std::fs::read(path).map_err(|e| TextureError::Read {
        path: source.to_string(),
        message: e.to_string(),
    })?;
    decode(&bytes, &ext(path), source, import)
}

/// The image in `bytes` (a file with extension `extension`, lower case, no dot, named
/// `source` in errors) as decoded, its size checked before anything is allocated, and
/// whether its samples are floats (linear light).
pub fn decode_image(
    bytes: &[u8],
    extension: &str,
    source: &str,
) -> Result<(DynamicImage, bool), TextureError> {
    if bytes.starts_with(b"version https://git-lfs.github.com/spec/") {
        return Err(TextureError::LfsPointer {
            path: source.to_string(),
        });
    }
    let decode_err = |format: &str, message: String| TextureError::Decode {
        path: source.to_string(),
        format: format.to_string(),
        message,
    };
    let too_large = |width, height| TextureError::TooLarge {
        path: source.to_string(),
        width,
        height,
    };
    Ok(if extension == "psd" {
        let (w, h) = psd_size(bytes).ok_or_else(|| decode_err("PSD", "no PSD header".into()))?;
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(too_large(w, h));
        }
        let composite = psd_composite(bytes, w, h).map_err(|m| decode_err("PSD", m))?;
        let rgba = decode_psd(&composite).map_err(|m| decode_err("PSD", m))?;
        let img = image::RgbaImage::from_raw(w, h, rgba)
            .ok_or_else(|| decode_err("PSD", "composite size does not match header".into()))?;
        (DynamicImage::ImageRgba8(img), false)
    } else {
        let format = match extension {
            "png" => ImageFormat::Png,
            "jpg" | "jpeg" => ImageFormat::Jpeg,
            "tga" => ImageFormat::Tga,
            "tif" | "tiff" => ImageFormat::Tiff,
            "exr" => ImageFormat::OpenExr,
            "hdr" => ImageFormat::Hdr,
            "bmp" => ImageFormat::Bmp,
            _ => {
                return Err(TextureError::Unsupported {
                    path: source.to_string(),
                    ext: extension.to_string(),
                })
            }
        };
        let name = format!("{format:?}").to_uppercase();
        // Read the header alone first, so a lying size is refused before any allocation.
        let (w, h) = ImageReader::with_format(Cursor::new(bytes), format)
            .into_dimensions()
            .map_err(|e| decode_err(&name, e.to_string()))?;
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(too_large(w, h));
        }
        let mut reader = ImageReader::with_format(Cursor::new(bytes), format);
        let mut limits = Limits::default();
        limits.max_image_width = Some(MAX_SIDE);
        limits.max_image_height = Some(MAX_SIDE);
        // The crate's default cap (512 MiB) refused images Unity imports, a 16384² RGBA
        // PNG or an 8192² float EXR among them: allow what the checked size decodes to in
        // the widest pixel format (RGBA, 32-bit float), never less than that default.
        let default = limits.max_alloc.unwrap_or(u64::MAX);
        let cap = default.max(w as u64 * h as u64 * 16);
        limits.max_alloc = Some(cap);
        if format == ImageFormat::OpenExr {
            exr_within(bytes, cap).map_err(|m| decode_err(&name, m))?;
        }
        reader.limits(limits);
        let img = reader
            .decode()
            .map_err(|e| decode_err(&name, e.to_string()))?;
        let float = matches!(
            img,
            DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
        );
        (img, float)
    })
}

/// An image as linear RGB, bottom row first: what a sky reads.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<glam::Vec3>,
}

/// The image at `path` (named `source`) as linear RGB, at the size `import` gives it when
/// `resize`, else at its own: float images as they are, 8-bit ones decoded from sRGB when
/// the import says so.
pub fn load_linear(
    path: &Path,
    source: &str,
    import: &Import,
    resize: bool,
) -> Result<LinearImage, TextureError> {
    let bytes = std::fs::read(path).map_err(|e| TextureError::Read {
        path: source.to_string(),
        message: e.to_string(),
    })?;
    let (image, float) = decode_image(&bytes, &ext(path), source)?;
    let mut img = image.into_rgb32f();
    // The sRGB curve itself, not the 8-bit table: 16-bit images keep their precision.
    if !float && import.srgb {
        img.pixels_mut()
            .for_each(|p| p.0 = p.0.map(crate::material::srgb_to_linear));
    }
    let (w, h) = if resize {
        import.imported_size(img.width(), img.height())
    } else {
        img.dimensions()
    };
    if (w, h) != img.dimensions() {
        img = image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle);
    }
    // Image files list the top row first; one pass turns them over.
    let rgb = img
        .rows()
        .rev()
        .flatten()
        .map(|p| glam::Vec3::from_array(p.0))
        .collect();
    Ok(LinearImage {
        width: w,
        height: h,
        rgb,
    })
}

/// [`load`] on bytes already read, with the file's extension (lower case, no dot).
pub fn decode(
    bytes: &[u8],
    extension: &str,
    source: &str,
    import: &Import,
) -> Result<Texture, TextureError> {
    let decode_err = |format: &str, message: String| TextureError::Decode {
        path: source.to_string(),
        format: format.to_string(),
        message,
    };
    let (image, float) = decode_image(bytes, extension, source)?;
    let (w, h) = import.imported_size(image.width(), image.height());
    let filter = image::imageops::FilterType::Triangle;
    // Float images hold linear light: stored sRGB-encoded, 8 bits lose least there.
    let (rows, srgb) = if float {
        let mut img = image.into_rgba32f();
        if (w, h) != img.dimensions() {
            img = image::imageops::resize(&img, w, h, filter);
        }
        let bytes: Vec<u8> = img
            .pixels()
            .flat_map(|p| {
                let q = |c: f32| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
                let encode = |c: f32| q(formats::srgb::linear_to_srgb(c.clamp(0.0, 1.0)));
                [encode(p[0]), encode(p[1]), encode(p[2]), q(p[3])]
            })
            .collect();
        (bytes, true)
    } else {
        let mut img = image.into_rgba8();
        if (w, h) != img.dimensions() {
            img = image::imageops::resize(&img, w, h, filter);
        }
        (img.into_raw(), import.srgb)
    };
    // Image files list the top row first; Unity's v = 0 is the bottom row.
    let row = w as usize * 4;
    let mut texels: Vec<u8> = rows.chunks_exact(row).rev().flatten().copied().collect();
    if import.flip_green {
        texels
            .iter_mut()
            .skip(1)
            .step_by(4)
            .for_each(|g| *g = 255 - *g);
    }
    let t = Texture {
        source: source.to_string(),
        width: w,
        height: h,
        texels,
        srgb,
        wrap_u: import.wrap_u,
        wrap_v: import.wrap_v,
        filter: import.filter,
        mipmaps: import.mipmaps,
    };
    t.validate().map_err(|m| decode_err("image", m))?;
    Ok(t)
}

/// Whether every part of an EXR fits in `cap` bytes across all its channels. The size
/// checked above is the display window's, but the `exr` crate decompresses blocks of every
/// channel of the data window, sized from the header alone before the allocation cap
/// applies: 40,003 channels over a 16384×16 data window asked for 42 GB and aborted.
fn exr_within(bytes: &[u8], cap: u64) -> Result<(), String> {
    use exr::math::Vec2;
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| e.to_string())?;
    for header in meta.headers.iter() {
        let Vec2(w, h) = header.layer_size;
        let need = (w as u64 * h as u64).saturating_mul(header.channels.bytes_per_pixel as u64);
        if need > cap {
            let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
            let Vec2(dw, dh) = header.shared_attributes.display_window.size;
            return Err(format!(
                "its {w}×{h} data window of {} channels takes {:.0} MiB, more than the {:.0} \
                 MiB a {dw}×{dh} texture may",
                header.channels.list.len(),
                mib(need),
                mib(cap),
            ));
        }
    }
    Ok(())
}

/// Width and height from a PSD header (`8BPS`, big-endian height then width).
fn psd_size(bytes: &[u8]) -> Option<(u32, u32)> {
    if bytes.len() < 26 || &bytes[..4] != b"8BPS" {
        return None;
    }
    Some((be32(bytes, 18)?, be32(bytes, 14)?))
}

fn be32(b: &[u8], i: usize) -> Option<u32> {
    Some(u32::from_be_bytes(b.get(i..i + 4)?.try_into().ok()?))
}

/// The bytes to hand the `psd` crate: the header and the image data (the flattened
/// composite), with the colour mode, image resource and layer sections emptied between
/// them. The crate parses those sections in full although only the composite is read: a
/// count in an image resource sizes a table before anything is read (an 88-byte file
/// asked for 554 GB, an abort no `catch_unwind` survives), and layers it cannot parse
/// (ZIP-compressed channels, which Photoshop writes) failed files whose composite is fine.
///
/// Refused, with the reason, when the image data holds fewer bytes than the header
/// promises (the crate reads a truncated composite as black instead of failing) or its RLE
/// runs decode to more than the header's size (the crate decodes every run, 129 bytes
/// from two packed ones, whatever the size). The image data is cut where it ends, for raw
/// data where the header says: the crate writes raw bytes past that end out of bounds.
fn psd_composite(bytes: &[u8], w: u32, h: u32) -> Result<Vec<u8>, String> {
    let truncated = || "truncated".to_string();
    let be16 = |i: usize| {
        bytes
            .get(i..i + 2)
            .map(|s| u16::from_be_bytes([s[0], s[1]]))
            .ok_or_else(truncated)
    };
    let (channels, depth) = (be16(12)? as u64, be16(22)? as u64);
    let mut at = 26usize;
    for _ in 0..3 {
        let len = be32(bytes, at).ok_or_else(truncated)?;
        at = at.saturating_add(4).saturating_add(len as usize);
    }
    let data = bytes.get(at.saturating_add(2)..).unwrap_or_default();
    let plane = h as u64 * (w as u64 * depth).div_ceil(8);
    let len = match be16(at)? {
        0 => channels * plane,
        1 => psd_rle_len(data, channels, h, plane)?,
        2 | 3 => return Err("ZIP-compressed image data is not supported".into()),
        c => return Err(format!("unknown image data compression {c}")),
    };
    if (data.len() as u64) < len {
        return Err(truncated());
    }
    let mut out = bytes[..26].to_vec();
    out.extend([0; 12]);
    out.extend(&bytes[at..at + 2 + len as usize]);
    Ok(out)
}

/// The length of RLE image data (the packed length of every row, then the rows), or why it
/// is refused: a channel whose runs decode to more than its `plane` bytes.
fn psd_rle_len(data: &[u8], channels: u64, h: u32, plane: u64) -> Result<u64, String> {
    let rows = (channels * h as u64) as usize;
    let table = data.get(..rows * 2).ok_or("truncated")?;
    let mut at = table.len();
    // The crate decodes each channel's rows as one stream, so the bound is per channel.
    for channel in table.chunks(h as usize * 2) {
        let packed: usize = channel
            .chunks_exact(2)
            .map(|n| u16::from_be_bytes([n[0], n[1]]) as usize)
            .sum();
        let runs = data.get(at..at + packed).ok_or("truncated")?;
        at += packed;
        let (mut i, mut decoded) = (0, 0u64);
        while i < runs.len() {
            let n = runs[i] as i8;
            (i, decoded) = match n {
                -128 => (i + 1, decoded),
                0.. => (i + 2 + n as usize, decoded + 1 + n as u64),
                _ => (i + 2, decoded + 1 + n.unsigned_abs() as u64),
            };
        }
        if decoded > plane {
            return Err("RLE image data decodes past the size in the header".into());
        }
    }
    Ok(at as u64)
}

/// The flattened composite of a PSD as RGBA, top row first. The `psd` crate indexes
/// without checking on some malformed files, so its panics are caught and reported as a
/// decode error instead of taking the converter down.
fn decode_psd(bytes: &[u8]) -> Result<Vec<u8>, String> {
    IN_PSD.set(true);
    let r = std::panic::catch_unwind(|| psd::Psd::from_bytes(bytes).map(|p| p.rgba()));
    IN_PSD.set(false);
    match r {
        Ok(Ok(rgba)) => Ok(rgba),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => Err("malformed PSD".to_string()),
    }
}

thread_local! {
    static IN_PSD: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether this thread is inside the PSD decoder, whose panics become a decode error: a
/// program's panic hook can stay silent for those (the warning says what happened) and
/// still report every other panic.
pub fn panic_is_caught_decode() -> bool {
    IN_PSD.get()
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{Rgba, RgbaImage};

    fn mat(text: &str) -> Node {
        yaml::parse(text)
    }

    #[test]
    fn albedo_slot_modern_layout_follows_the_shader() {
        let urp = mat(
            "m_Shader: {fileID: 4800000, guid: 933532a4fcc9baf4fa0491de14d08ed7, type: 3}
m_SavedProperties:
  m_TexEnvs:
  - _BaseMap:
      m_Texture: {fileID: 2800000, guid: aaaa, type: 3}
      m_Scale: {x: -2, y: 3.5}
      m_Offset: {x: 0.25, y: 0}
  - _MainTex:
      m_Texture: {fileID: 2800000, guid: bbbb, type: 3}
      m_Scale: {x: 1, y: 1}
      m_Offset: {x: 0, y: 0}
",
        );
        let s = albedo_slot(&urp).unwrap();
        assert_eq!(s.property, "_BaseMap");
        assert_eq!(s.guid, "aaaa");
        assert_eq!(s.tiling.scale, [-2.0, 3.5]);
        assert_eq!(s.tiling.offset, [0.25, 0.0]);
        // URP with an empty _BaseMap draws untextured, whatever the stale _MainTex says.
        let empty = mat(
            "m_Shader: {fileID: 4800000, guid: 933532a4fcc9baf4fa0491de14d08ed7, type: 3}
m_SavedProperties:
  m_TexEnvs:
  - _BaseMap:
      m_Texture: {fileID: 0}
  - _MainTex:
      m_Texture: {fileID: 2800000, guid: bbbb, type: 3}
",
        );
        assert_eq!(albedo_slot(&empty), None);
    }

    #[test]
    fn normal_slot_needs_the_keyword_and_takes_the_main_tiling() {
        let standard = |keywords: &str| {
            mat(&format!(
                "m_Shader: {{fileID: 46, guid: 0000000000000000f000000000000000, type: 0}}
{keywords}m_SavedProperties:
  m_TexEnvs:
  - _BumpMap:
      m_Texture: {{fileID: 2800000, guid: nnnn, type: 3}}
      m_Scale: {{x: 1, y: 1}}
      m_Offset: {{x: 0, y: 0}}
  - _MainTex:
      m_Texture: {{fileID: 0}}
      m_Scale: {{x: 4, y: 2}}
      m_Offset: {{x: 0.5, y: 0}}
  m_Floats:
  - _BumpScale: 0.25
"
            ))
        };
        let (s, scale) =
            normal_slot(&standard("m_ShaderKeywords: _EMISSION _NORMALMAP\n")).unwrap();
        assert_eq!(
            (s.property.as_str(), s.guid.as_str(), scale),
            ("_BumpMap", "nnnn", 0.25)
        );
        // Unity's shaders tile every map as the main texture, empty or not.
        assert_eq!(s.tiling.scale, [4.0, 2.0]);
        assert_eq!(s.tiling.offset, [0.5, 0.0]);
        let valid = standard("m_ValidKeywords:\n- _NORMALMAP\n");
        assert!(normal_slot(&valid).is_some());
        // A keyword list without _NORMALMAP: the shader samples no normal map.
        assert_eq!(
            normal_slot(&standard("m_ShaderKeywords: _EMISSION\n")),
            None
        );
        assert_eq!(normal_slot(&standard("m_ValidKeywords: []\n")), None);
        // A file without any keyword list uses the map it names.
        assert!(normal_slot(&standard("")).is_some());

        let hdrp = mat(
            "m_Shader: {fileID: 4800000, guid: 6e4ae4064600d784cac1e41a9e6f2e59, type: 3}
m_ShaderKeywords: _NORMALMAP _NORMALMAP_TANGENT_SPACE
m_SavedProperties:
  m_TexEnvs:
  - _BaseColorMap:
      m_Texture: {fileID: 0}
      m_Scale: {x: 3, y: 3}
      m_Offset: {x: 0, y: 0}
  - _BumpMap:
      m_Texture: {fileID: 2800000, guid: stale, type: 3}
  - _NormalMap:
      m_Texture: {fileID: 2800000, guid: hhhh, type: 3}
  m_Floats:
  - _BumpScale: 1
  - _NormalScale: 1.5
",
        );
        let (s, scale) = normal_slot(&hdrp).unwrap();
        assert_eq!(
            (s.property.as_str(), s.guid.as_str(), scale),
            ("_NormalMap", "hhhh", 1.5)
        );
        assert_eq!(s.tiling.scale, [3.0, 3.0]);
        let empty = mat("m_ShaderKeywords: _NORMALMAP
m_SavedProperties:
  m_TexEnvs:
  - _BumpMap:
      m_Texture: {fileID: 0}
");
        assert_eq!(normal_slot(&empty), None);
    }

    #[test]
    fn metallic_slot_follows_the_shader_its_keyword_and_workflow() {
        let material = |shader: &str, keywords: &str, floats: &str| {
            mat(&format!(
                "m_Shader: {{{shader}, type: 0}}
{keywords}m_SavedProperties:
  m_TexEnvs:
  - _MetallicGlossMap:
      m_Texture: {{fileID: 2800000, guid: mmmm, type: 3}}
  - _MainTex:
      m_Texture: {{fileID: 0}}
      m_Scale: {{x: 3, y: 1}}
      m_Offset: {{x: 0, y: 0.5}}
  m_Floats:
  - _Glossiness: 0.2
{floats}"
            ))
        };
        let standard = format!("fileID: 46, guid: {BUILTIN_SHADERS}");
        let specular = format!("fileID: 45, guid: {BUILTIN_SHADERS}");
        let legacy = format!("fileID: 7, guid: {BUILTIN_SHADERS}");
        let urp = format!("fileID: 4800000, guid: {URP_LIT}");
        let hdrp = format!("fileID: 4800000, guid: {HDRP_LIT}");
        let on = "m_ShaderKeywords: _METALLICGLOSSMAP _NORMALMAP
";
        let off = "m_ShaderKeywords: _NORMALMAP
";
        let scale = "  - _GlossMapScale: 0.6
";
        let (s, smoothness) = metallic_slot(&material(&standard, on, scale)).unwrap();
        assert_eq!(
            (s.guid.as_str(), smoothness, s.tiling.scale, s.tiling.offset),
            ("mmmm", 0.6, [3.0, 1.0], [0.0, 0.5]),
            "the map, _GlossMapScale and the albedo's tiling"
        );
        assert_eq!(metallic_slot(&material(&standard, on, "")).unwrap().1, 1.0);
        assert!(metallic_slot(&material(&standard, "", scale)).is_some());
        assert!(metallic_slot(&material(&standard, off, scale)).is_none());
        // A stale slot left by an earlier shader is not read.
        assert!(metallic_slot(&material(&specular, on, scale)).is_none());
        assert!(metallic_slot(&material(&legacy, on, scale)).is_none());
        assert!(metallic_slot(&material(&hdrp, on, scale)).is_none());
        // URP Lit: its own keyword, `_Smoothness` as the scale, the metallic workflow only.
        let urp_on = "m_ValidKeywords:
- _METALLICSPECGLOSSMAP
";
        let smooth = "  - _Smoothness: 1.5
  - _WorkflowMode: 1
";
        assert_eq!(
            metallic_slot(&material(&urp, urp_on, smooth)).unwrap().1,
            1.0
        );
        assert_eq!(metallic_slot(&material(&urp, urp_on, "")).unwrap().1, 0.5);
        assert!(metallic_slot(&material(&urp, on, smooth)).is_none());
        let urp_specular = "m_ValidKeywords:
- _METALLICSPECGLOSSMAP
- _SPECULAR_SETUP
";
        assert!(metallic_slot(&material(&urp, urp_specular, smooth)).is_none());
        let workflow = "  - _WorkflowMode: 0
";
        assert!(metallic_slot(&material(&urp, "", workflow)).is_none());
        assert!(metallic_slot(&material(&urp, "", smooth)).is_some());
    }

    #[test]
    fn occlusion_slot_follows_the_shader_and_keeps_the_strength_within_0_to_1() {
        let material = |shader: &str, keywords: &str, strength: &str| {
            mat(&format!(
                "m_Shader: {{fileID: 4800000, guid: {shader}, type: 3}}
{keywords}m_SavedProperties:
  m_TexEnvs:
  - _OcclusionMap:
      m_Texture: {{fileID: 2800000, guid: oooo, type: 3}}
  - _MainTex:
      m_Texture: {{fileID: 0}}
      m_Scale: {{x: 2, y: 2}}
      m_Offset: {{x: 0, y: 0}}
  m_Floats:
{strength}"
            ))
        };
        let standard = BUILTIN_SHADERS;
        let (s, strength) = occlusion_slot(&material(
            standard,
            "",
            "  - _OcclusionStrength: 0.4
",
        ))
        .unwrap();
        assert_eq!(
            (s.guid.as_str(), strength, s.tiling.scale),
            ("oooo", 0.4, [2.0, 2.0])
        );
        // The Standard shader needs no keyword; URP Lit does, where keywords are listed.
        let none = "m_ShaderKeywords: _EMISSION
";
        assert!(occlusion_slot(&material(standard, none, "")).is_some());
        assert_eq!(
            occlusion_slot(&material(standard, none, "")).unwrap().1,
            1.0
        );
        assert!(occlusion_slot(&material(URP_LIT, none, "")).is_none());
        let urp = material(
            URP_LIT,
            "m_ValidKeywords:
- _OCCLUSIONMAP
",
            "  - _OcclusionStrength: 3
",
        );
        assert_eq!(occlusion_slot(&urp).unwrap().1, 1.0, "kept within 0–1");
        assert!(occlusion_slot(&material(HDRP_LIT, "", "")).is_none());
    }

    #[test]
    fn emission_slot_takes_the_main_tiling() {
        let m = mat("m_SavedProperties:
  m_TexEnvs:
  - _EmissionMap:
      m_Texture: {fileID: 2800000, guid: eeee, type: 3}
      m_Scale: {x: 1, y: 1}
      m_Offset: {x: 0, y: 0}
  - _MainTex:
      m_Texture: {fileID: 2800000, guid: aaaa, type: 3}
      m_Scale: {x: 2, y: 2}
      m_Offset: {x: 0, y: 0.5}
");
        let s = emission_slot(&m).unwrap();
        assert_eq!(
            (s.property.as_str(), s.guid.as_str()),
            ("_EmissionMap", "eeee")
        );
        assert_eq!((s.tiling.scale, s.tiling.offset), ([2.0, 2.0], [0.0, 0.5]));
        let none = mat(
            "m_SavedProperties:\n  m_TexEnvs:\n  - _EmissionMap:\n      m_Texture: {fileID: 0}\n",
        );
        assert_eq!(emission_slot(&none), None);
    }

    #[test]
    fn albedo_slot_legacy_layout() {
        let old = mat(
            "m_Shader: {fileID: 46, guid: 0000000000000000f000000000000000, type: 0}
m_SavedProperties:
  m_TexEnvs:
    data:
      first:
        name: _BumpMap
      second:
        m_Texture: {fileID: 2800000, guid: cccc, type: 3}
        m_Scale: {x: 1, y: 1}
        m_Offset: {x: 0, y: 0}
    data:
      first:
        name: _MainTex
      second:
        m_Texture: {fileID: 2800000, guid: dddd, type: 3}
        m_Scale: {x: 10, y: 5}
        m_Offset: {x: 0, y: 0.5}
",
        );
        let s = albedo_slot(&old).unwrap();
        assert_eq!((s.property.as_str(), s.guid.as_str()), ("_MainTex", "dddd"));
        assert_eq!(s.tiling.scale, [10.0, 5.0]);
        assert_eq!(s.tiling.offset, [0.0, 0.5]);
    }

    #[test]
    fn import_settings() {
        let im = Import::parse(
            "TextureImporter:
  mipmaps:
    enableMipMap: 0
    sRGBTexture: 0
  maxTextureSize: 2048
  textureSettings:
    filterMode: 2
    wrapU: 1
    wrapV: 2
  nPOTScale: 3
  alphaIsTransparency: 1
  bumpmap:
    convertToNormalMap: 1
    flipGreenChannel: 1
  textureType: 1
  textureShape: 2
  generateCubemap: 2
  platformSettings:
  - buildTarget: DefaultTexturePlatform
    maxTextureSize: 256
",
        );
        assert_eq!(
            im,
            Import {
                srgb: false,
                wrap_u: Wrap::Clamp,
                wrap_v: Wrap::Mirror,
                filter: Filter::Trilinear,
                mipmaps: false,
                max_size: 256,
                npot: Npot::ToSmaller,
                alpha_is_transparency: true,
                from_grayscale: true,
                flip_green: true,
                cube: true,
                cube_mapping: 2,
            }
        );
        let old = Import::parse(
            "TextureImporter:\n  linearTexture: 1\n  textureSettings:\n    filterMode: 0\n    wrapMode: 1\n",
        );
        assert!(!old.srgb);
        assert_eq!((old.wrap_u, old.wrap_v), (Wrap::Clamp, Wrap::Clamp));
        assert_eq!(old.filter, Filter::Point);
        assert_eq!(Import::parse(""), Import::default());
    }

    #[test]
    fn imported_sizes() {
        let im = Import::default();
        assert_eq!(im.imported_size(640, 200), (512, 256));
        assert_eq!(im.imported_size(768, 96), (1024, 128));
        assert_eq!(im.imported_size(4096, 1024), (2048, 512));
        let none = Import {
            npot: Npot::None,
            max_size: 1000,
            ..Import::default()
        };
        assert_eq!(none.imported_size(3000, 1500), (1000, 500));
        assert_eq!(none.imported_size(300, 7), (300, 7));
    }

    fn encode(img: &RgbaImage, format: ImageFormat) -> Vec<u8> {
        let mut out = Cursor::new(Vec::new());
        img.write_to(&mut out, format).unwrap();
        out.into_inner()
    }

    /// Top row (as written): red, green; bottom row: blue, grey 128.
    fn four_colours() -> RgbaImage {
        let mut img = RgbaImage::new(2, 2);
        img.put_pixel(0, 0, Rgba([255, 0, 0, 255]));
        img.put_pixel(1, 0, Rgba([0, 255, 0, 255]));
        img.put_pixel(0, 1, Rgba([0, 0, 255, 255]));
        img.put_pixel(1, 1, Rgba([128, 128, 128, 255]));
        img
    }

    #[test]
    fn texel_0_0_is_the_bottom_left() {
        for (format, ext) in [
            (ImageFormat::Png, "png"),
            (ImageFormat::Tga, "tga"),
            (ImageFormat::Tiff, "tif"),
            (ImageFormat::Bmp, "bmp"),
        ] {
            let bytes = encode(&four_colours(), format);
            let t = decode(&bytes, ext, "t", &Import::default()).unwrap();
            assert_eq!((t.width, t.height), (2, 2), "{ext}");
            assert_eq!(t.texel(0, 0), [0.0, 0.0, 1.0, 1.0], "{ext}");
            assert_eq!(t.texel(0, 1), [1.0, 0.0, 0.0, 1.0], "{ext}");
            assert_eq!(t.texel(1, 1), [0.0, 1.0, 0.0, 1.0], "{ext}");
            let grey = t.texel(1, 0);
            assert!((grey[0] - 0.2158).abs() < 1e-4, "{ext}: {grey:?}");
            assert_eq!(grey[3], 1.0);
        }
        // sRGBTexture 0 keeps the code as a linear value.
        let linear = Import {
            srgb: false,
            ..Import::default()
        };
        let t = decode(
            &encode(&four_colours(), ImageFormat::Png),
            "png",
            "t",
            &linear,
        )
        .unwrap();
        assert_eq!(t.texel(1, 0)[0], 128.0 / 255.0);
        // A normal map imported with Flip Green Channel: green inverted, nothing else.
        let flipped = Import {
            flip_green: true,
            ..linear
        };
        let f = decode(
            &encode(&four_colours(), ImageFormat::Png),
            "png",
            "t",
            &flipped,
        )
        .unwrap();
        for (a, b) in t.texels.chunks(4).zip(f.texels.chunks(4)) {
            assert_eq!([b[0], 255 - b[1], b[2], b[3]], [a[0], a[1], a[2], a[3]]);
        }
    }

    #[test]
    fn exr_is_linear_light() {
        let mut img = image::Rgba32FImage::new(1, 1);
        img.put_pixel(0, 0, Rgba([0.2158, 1.0, 0.0, 1.0]));
        let mut out = Cursor::new(Vec::new());
        DynamicImage::ImageRgba32F(img)
            .write_to(&mut out, ImageFormat::OpenExr)
            .unwrap();
        let t = decode(out.get_ref(), "exr", "t", &Import::default()).unwrap();
        assert!(t.srgb);
        assert_eq!(&t.texels, &[128, 255, 0, 255]);
    }

    /// A minimal flattened PSD: RGB, 8 bits, no layers, raw image data (planar).
    fn psd_2x2() -> Vec<u8> {
        psd_2x2_with(&[], &[], &psd_2x2_raw())
    }

    /// Image data: raw, the R plane (top row first), then G, then B.
    fn psd_2x2_raw() -> Vec<u8> {
        let mut b = 0u16.to_be_bytes().to_vec();
        b.extend([255, 0, 0, 128, 0, 255, 0, 128, 0, 0, 255, 128]);
        b
    }

    /// A 2×2 RGB PSD with the given image resources, layer and mask section and image data.
    fn psd_2x2_with(resources: &[u8], layers: &[u8], image_data: &[u8]) -> Vec<u8> {
        let mut b = b"8BPS".to_vec();
        b.extend(1u16.to_be_bytes());
        b.extend([0; 6]);
        b.extend(3u16.to_be_bytes()); // channels
        b.extend(2u32.to_be_bytes()); // height
        b.extend(2u32.to_be_bytes()); // width
        b.extend(8u16.to_be_bytes()); // depth
        b.extend(3u16.to_be_bytes()); // RGB
        b.extend(0u32.to_be_bytes()); // colour mode data
        b.extend((resources.len() as u32).to_be_bytes());
        b.extend(resources);
        b.extend((layers.len() as u32).to_be_bytes());
        b.extend(layers);
        b.extend(image_data);
        b
    }

    /// A layer and mask section with one RGB layer over `rect` (top, left, bottom, right),
    /// each channel `compression` then `channel`.
    fn psd_layer(rect: [i32; 4], compression: u16, channel: &[u8]) -> Vec<u8> {
        let mut info = 1i16.to_be_bytes().to_vec(); // layer count
        for v in rect {
            info.extend(v.to_be_bytes());
        }
        info.extend(3u16.to_be_bytes());
        for id in 0..3i16 {
            info.extend(id.to_be_bytes());
            info.extend((2 + channel.len() as u32).to_be_bytes());
        }
        info.extend(b"8BIMnorm");
        info.extend([255, 0, 2, 0]); // opacity, clipping, visible, filler
        info.extend(12u32.to_be_bytes()); // no mask, no blending ranges, the name "L"
        info.extend([0; 8]);
        info.extend([1, b'L', 0, 0]);
        for _ in 0..3 {
            info.extend(compression.to_be_bytes());
            info.extend(channel);
        }
        if info.len() % 2 == 1 {
            info.push(0);
        }
        let mut section = (info.len() as u32).to_be_bytes().to_vec();
        section.extend(info);
        section.extend([0; 4]); // no global layer mask
        section
    }

    /// An image resource section holding a slices resource whose descriptor claims `count`
    /// fields and holds none.
    fn psd_slices(count: u32) -> Vec<u8> {
        let mut body = 7i32.to_be_bytes().to_vec(); // slices as a descriptor
        body.extend(16i32.to_be_bytes());
        body.extend([0; 8]); // no name, a four-byte class ID
        body.extend(b"null");
        body.extend(count.to_be_bytes());
        let mut block = b"8BIM".to_vec();
        block.extend(1050u16.to_be_bytes());
        block.extend([0, 0]); // no name
        block.extend((body.len() as u32).to_be_bytes());
        block.extend(body);
        block
    }

    #[test]
    fn psd_composite() {
        let t = decode(&psd_2x2(), "psd", "t.psd", &Import::default()).unwrap();
        assert_eq!(&t.texels[..4], &[0, 0, 255, 255]);
        assert_eq!(&t.texels[12..], &[0, 255, 0, 255]);
        // Bytes after the raw image data are ignored (the fuzzer's find: the psd crate
        // wrote them past the end of its buffer).
        let mut padded = psd_2x2();
        padded.extend([0; 20]);
        let p = decode(&padded, "psd", "t.psd", &Import::default()).unwrap();
        assert_eq!(p, t);
    }

    #[test]
    fn psd_sections_before_the_composite_are_not_parsed() {
        let im = Import::default();
        let plain = decode(&psd_2x2(), "psd", "t.psd", &im).unwrap();
        let raw = psd_2x2_raw();
        // Before the crate was handed the composite alone: a layer a million texels on a
        // side (its RLE row table runs past the file) and ZIP-compressed layer channels
        // were refused as malformed, and the resource's 2³¹ fields aborted the process.
        let huge = psd_layer([0, 0, 1_000_000, 1_000_000], 1, &[0, 1, 255, 0]);
        let zip = psd_layer([0, 0, 2, 2], 2, &[0x78, 0x9c, 3, 0, 0, 0, 0, 1]);
        for (resources, layers) in [
            (vec![], huge),
            (vec![], zip),
            (psd_slices(0x7fff_ffff), vec![]),
        ] {
            let psd = psd_2x2_with(&resources, &layers, &raw);
            let t = decode(&psd, "psd", "t.psd", &im).unwrap();
            assert_eq!(t, plain);
        }
    }

    #[test]
    fn psd_rle_composite() {
        let im = Import::default();
        let plain = decode(&psd_2x2(), "psd", "t.psd", &im).unwrap();
        let rle = |first_row: &[u8]| {
            let mut rows = vec![first_row.to_vec()];
            for row in [[0, 128], [0, 255], [0, 128], [0, 0], [255, 128]] {
                rows.push(vec![1, row[0], row[1]]); // a literal run of two
            }
            let mut b = 1u16.to_be_bytes().to_vec();
            for row in &rows {
                b.extend((row.len() as u16).to_be_bytes());
            }
            b.extend(rows.concat());
            psd_2x2_with(&[], &[], &b)
        };
        let t = decode(&rle(&[1, 255, 0]), "psd", "t.psd", &im).unwrap();
        assert_eq!(t, plain);
        // A run of 128 in a 2-texel row: the crate would decode it all.
        let long = decode(&rle(&[0x81, 7]), "psd", "t.psd", &im).unwrap_err();
        assert!(long.to_string().contains("RLE"), "{long}");
        let mut zip = psd_2x2();
        zip[39] = 2;
        let zip = decode(&zip, "psd", "t.psd", &im).unwrap_err();
        assert!(zip.to_string().contains("ZIP"), "{zip}");
    }

    #[test]
    fn images_decoding_past_512_mib_are_read() {
        // 16384 × 8200 RGBA: 537 MB decoded, past the image crate's default cap, and
        // imported as Unity does at the default size limit, 2048 × 1024. The zeroed pixel
        // buffer stays mostly unbacked pages: only the red corner is written.
        let (w, h) = (16384u32, 8200u32);
        let mut img = RgbaImage::from_raw(w, h, vec![0; w as usize * h as usize * 4]).unwrap();
        for y in 0..256 {
            for x in 0..256 {
                img.put_pixel(x, y, Rgba([255, 0, 0, 255]));
            }
        }
        let png = encode(&img, ImageFormat::Png);
        let t = decode(&png, "png", "big.png", &Import::default()).unwrap();
        assert_eq!((t.width, t.height), (2048, 1024));
        // The top-left corner, where rows bottom first put it last; the far corner.
        let texel = |x: usize, y: usize| &t.texels[(y * 2048 + x) * 4..][..4];
        assert_eq!(texel(0, 1023), [255, 0, 0, 255]);
        assert_eq!(texel(2047, 0), [0, 0, 0, 0]);
    }

    #[test]
    fn exr_data_windows_past_their_image_are_refused_before_decoding() {
        // A 4×4 RGB image whose 4096×16 data window holds 3,000 more float channels
        // (787 MB): the `exr` crate sized its block buffers by them before reading a byte
        // of pixels.
        let attr = |name: &str, kind: &str, data: &[u8]| {
            let mut b = format!("{name}\0{kind}\0").into_bytes();
            b.extend((data.len() as i32).to_le_bytes());
            b.extend(data);
            b
        };
        let ints = |v: [i32; 4]| v.iter().flat_map(|i| i.to_le_bytes()).collect::<Vec<u8>>();
        let mut channels = Vec::new();
        let names = ["B", "G", "R"].map(String::from);
        for name in names
            .into_iter()
            .chain((0..3000).map(|i| format!("c{i:04}")))
        {
            channels.extend(name.bytes().chain([0]));
            channels.extend([2, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0]); // float, 1×1
        }
        channels.push(0);
        let mut exr = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        exr.extend(attr("channels", "chlist", &channels));
        exr.extend(attr("compression", "compression", &[0]));
        exr.extend(attr("dataWindow", "box2i", &ints([0, 0, 4095, 15])));
        exr.extend(attr("displayWindow", "box2i", &ints([0, 0, 3, 3])));
        exr.extend(attr("lineOrder", "lineOrder", &[0]));
        exr.extend(attr("pixelAspectRatio", "float", &1f32.to_le_bytes()));
        exr.extend(attr("screenWindowCenter", "v2f", &[0; 8]));
        exr.extend(attr("screenWindowWidth", "float", &1f32.to_le_bytes()));
        exr.push(0);
        let first_block = exr.len() as u64 + 16 * 8;
        for line in 0..16 {
            exr.extend((first_block + line * 8).to_le_bytes());
        }
        for line in 0..16i32 {
            exr.extend(line.to_le_bytes());
            exr.extend(0i32.to_le_bytes());
        }
        let err = decode(&exr, "exr", "many.exr", &Import::default()).unwrap_err();
        assert!(
            err.to_string().contains(
                "its 4096×16 data window of 3003 channels takes 751 MiB, more than the 512 \
                 MiB a 4×4 texture may"
            ),
            "{err}"
        );
    }

    #[test]
    fn unreadable_files_are_errors() {
        let png = encode(&four_colours(), ImageFormat::Png);
        let im = Import::default();
        let truncated = decode(&png[..png.len() / 2], "png", "a.png", &im);
        assert!(
            matches!(truncated, Err(TextureError::Decode { .. })),
            "{truncated:?}"
        );
        let lying = decode(&png, "jpg", "a.jpg", &im);
        assert!(
            matches!(lying, Err(TextureError::Decode { .. })),
            "{lying:?}"
        );
        let lfs = decode(
            b"version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 12\n",
            "tif",
            "a.tif",
            &im,
        );
        assert!(matches!(lfs, Err(TextureError::LfsPointer { .. })));
        assert!(matches!(
            decode(b"DDS ", "dds", "a.dds", &im),
            Err(TextureError::Unsupported { .. })
        ));
        // An uncompressed TGA header claiming 60000×60000 texels and holding none.
        let mut tga = vec![0u8, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        tga.extend(60000u16.to_le_bytes());
        tga.extend(60000u16.to_le_bytes());
        tga.extend([32, 8]);
        let huge = decode(&tga, "tga", "a.tga", &im);
        assert!(
            matches!(huge, Err(TextureError::TooLarge { width: 60000, .. })),
            "{huge:?}"
        );
        let mut psd = psd_2x2();
        psd[14..18].copy_from_slice(&70000u32.to_be_bytes());
        assert!(matches!(
            decode(&psd, "psd", "a.psd", &im),
            Err(TextureError::TooLarge { .. })
        ));
        for cut in [10, 30, 40, 45, 51] {
            let r = decode(&psd_2x2()[..cut], "psd", "a.psd", &im);
            assert!(r.is_err(), "{cut}");
        }
        let err = truncated.unwrap_err().to_string();
        assert!(err.starts_with("a.png: "), "{err}");
    }
}
