//! The soups the accuracy sweep renders: Unity scenes converted on the fly, a real mesh
//! on a mirror floor and a textured checkerboard built in code, and a tiny scene for tests.

use anyhow::{bail, Context, Result};
use formats::texture::{Filter, Texture, TextureRef, Tiling, Wrap};
use formats::{
    Alpha, Ambient, AmbientMode, Camera, ClearFlags, Cull, Environment, Light, LightKind, Material,
    Object, Projection, Shadows, Soup,
};
use glam::{Vec2, Vec3};
use std::path::Path;

/// A named soup to sweep.
pub struct Scene {
    pub name: String,
    pub soup: Soup,
}

/// Convert a Unity scene with the workspace's converter.
pub fn unity_scene(name: &str, path: &Path) -> Result<Scene> {
    let soup = unity::convert(path, &unity::Options::default())
        .with_context(|| format!("{}: cannot convert the scene", path.display()))?;
    if soup.triangles.is_empty() {
        bail!("{}: the converted scene has no triangles", path.display());
    }
    Ok(Scene {
        name: name.into(),
        soup,
    })
}

fn quad(soup: &mut Soup, corners: [Vec3; 4], material: u32, object: u32) {
    let n = (corners[1] - corners[0])
        .cross(corners[2] - corners[0])
        .normalize();
    for t in [[0, 1, 2], [0, 2, 3]] {
        soup.push_triangle(t.map(|i| corners[i]), [n; 3], None);
        soup.tri_material.push(material);
        soup.tri_object.push(object);
    }
}

fn floor(soup: &mut Soup, half: f32, material: u32, object: u32) {
    // Counter-clockwise seen from above (+Y), so the face normal points up.
    quad(
        soup,
        [
            Vec3::new(-half, 0.0, -half),
            Vec3::new(-half, 0.0, half),
            Vec3::new(half, 0.0, half),
            Vec3::new(half, 0.0, -half),
        ],
        material,
        object,
    );
}

fn material(name: &str, color: Vec3, metallic: f32, smoothness: f32) -> Material {
    Material {
        name: name.into(),
        source: "accuracy".into(),
        color,
        metallic,
        smoothness,
        // The analytic references are diffuse.
        smoothness_in_alpha: false,
        pbs: false,
        highlights: false,
        reflections: false,
        reflectivity: None,
        emission: Vec3::ZERO,
        // Two-sided: the analytic references draw both faces.
        cull: Cull::None,
        normal_map: None,
        emission_map: None,
        occlusion_map: None,
        metallic_map: None,
        unlit: false,
        albedo_map: None,
        opacity: 1.0,
        alpha: Alpha::Opaque,
    }
}

fn point_light(name: &str, position: Vec3, intensity: f32, radius: f32) -> Light {
    Light {
        name: name.into(),
        kind: LightKind::Point,
        position,
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity,
        range: 30.0,
        attenuation: formats::Attenuation::BuiltIn,
        shadows: Shadows::Soft,
        shadow_radius: radius,
        shadow_strength: 1.0,
        culling_mask: u32::MAX,
    }
}

fn environment(background: Vec3, ambient: Vec3) -> Environment {
    Environment {
        clear: ClearFlags::SolidColor,
        background,
        ambient: Ambient {
            mode: AmbientMode::Flat,
            sky: ambient,
            equator: ambient,
            ground: ambient,
            intensity: 1.0,
        },
        fog: None,
        sky: None,
        color_space: formats::ColorSpace::Linear,
        shadow_distance: None,
        reflection: 0.0,
    }
}

fn look(position: Vec3, target: Vec3, fov_y: f32) -> Camera {
    let forward = (target - position).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    Camera {
        name: "accuracy camera".into(),
        position,
        forward,
        up: right.cross(forward),
        projection: Projection::Perspective { fov_y },
        near: 0.1,
        far: f32::INFINITY,
    }
}

/// An OBJ mesh scaled to 1 m tall, standing on a 6 m mirror floor, lit by a soft point
/// light and a hard directional light: mirror bounces, soft and hard shadows on real
/// geometry.
pub fn mesh_on_mirror(path: &Path) -> Result<Scene> {
    #[allow(clippy::needless_update)]
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _) =
        tobj::load_obj(path, &opts).with_context(|| format!("{}: cannot load", path.display()))?;
    let mut tris = vec![];
    for m in &models {
        let p = &m.mesh.positions;
        let v = |i: u32| -> Option<Vec3> {
            let i = i as usize * 3;
            p.get(i..i + 3).map(|c| Vec3::new(c[0], c[1], c[2]))
        };
        for f in m.mesh.indices.chunks_exact(3) {
            if let (Some(a), Some(b), Some(c)) = (v(f[0]), v(f[1]), v(f[2])) {
                if a.is_finite() && b.is_finite() && c.is_finite() {
                    tris.push([a, b, c]);
                }
            }
        }
    }
    if tris.is_empty() {
        bail!("{}: no triangles", path.display());
    }
    let [lo, hi] = crate::scenes::bounds(&tris);
    let size = hi - lo;
    let scale = 1.0 / size.y.max(1e-6);
    let centre = Vec3::new((lo.x + hi.x) / 2.0, lo.y, (lo.z + hi.z) / 2.0);
    let mut soup = Soup::empty();
    soup.materials = vec![
        material("mirror floor", Vec3::splat(0.8), 1.0, 0.75),
        material("mesh", Vec3::new(0.9, 0.55, 0.3), 0.0, 0.5),
    ];
    soup.objects = vec![
        Object::new("floor", "accuracy"),
        Object::new("mesh", path.display().to_string()),
    ];
    floor(&mut soup, 3.0, 0, 0);
    for t in &tris {
        let t = t.map(|v| (v - centre) * scale);
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.length_squared() == 0.0 || !n.is_finite() {
            soup.dropped_degenerate += 1;
            continue;
        }
        soup.push_triangle(t, [n.normalize(); 3], None);
        soup.tri_material.push(1);
        soup.tri_object.push(1);
    }
    soup.lights = vec![
        point_light("soft key", Vec3::new(1.5, 2.5, -1.5), 6.0, 0.4),
        Light {
            name: "hard sun".into(),
            kind: LightKind::Directional,
            position: Vec3::ZERO,
            direction: Vec3::new(0.4, -1.0, 0.6).normalize(),
            color: Vec3::new(1.0, 0.95, 0.85),
            intensity: 0.6,
            range: 0.0,
            attenuation: formats::Attenuation::BuiltIn,
            shadows: Shadows::Hard,
            shadow_radius: 0.0,
            shadow_strength: 1.0,
            culling_mask: u32::MAX,
        },
    ];
    soup.camera = look(Vec3::new(-1.2, 1.3, -2.6), Vec3::new(0.0, 0.45, 0.0), 45.0);
    soup.environment = environment(Vec3::new(0.25, 0.35, 0.55), Vec3::splat(0.05));
    soup.seal();
    soup.validate()
        .map_err(|e| anyhow::anyhow!("{}: built an invalid soup: {e}", path.display()))?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".into());
    Ok(Scene {
        name: format!("{stem}-on-mirror"),
        soup,
    })
}

/// A `size`×`size` texture of black and white squares `check` texels wide, sRGB,
/// trilinear, mip-mapped, repeating: what Unity imports a checker image as by default, bar
/// the filter mode (bilinear there).
pub fn checker_texture(size: u32, check: u32) -> Texture {
    let mut texels = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let c = if (x / check + y / check).is_multiple_of(2) {
                255
            } else {
                0
            };
            texels.extend_from_slice(&[c, c, c, 255]);
        }
    }
    Texture {
        source: "accuracy/checker.png".into(),
        width: size,
        height: size,
        texels,
        srgb: true,
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        filter: Filter::Trilinear,
        mipmaps: true,
    }
}

/// A floor 40 m wide receding 80 m from a camera 1 m above it, textured with a fine
/// checker (128 texels of 2-texel squares every 4 m: 6.25 cm squares) under a sun and a
/// little ambient light, no shadows: past a few metres a pixel covers many squares, so
/// unfiltered lookups alias (moiré) and only the texture filter decides the error.
pub fn checkerboard() -> Scene {
    let mut soup = Soup::empty();
    soup.textures = vec![checker_texture(128, 2)];
    soup.materials = vec![Material {
        normal_map: None,
        emission_map: None,
        occlusion_map: None,
        metallic_map: None,
        unlit: false,
        albedo_map: Some(TextureRef {
            texture: 0,
            tiling: Tiling::default(),
        }),
        ..material("checker", Vec3::splat(0.9), 0.0, 0.0)
    }];
    soup.objects = vec![Object::new("floor", "accuracy")];
    let (x0, x1, z0, z1) = (-20.0, 20.0, -2.0, 80.0);
    let corners = [
        Vec3::new(x0, 0.0, z0),
        Vec3::new(x0, 0.0, z1),
        Vec3::new(x1, 0.0, z1),
        Vec3::new(x1, 0.0, z0),
    ];
    // One texture repeat every 4 m.
    let uv = corners.map(|c| Vec2::new(c.x, c.z) / 4.0);
    for t in [[0, 1, 2], [0, 2, 3]] {
        soup.push_triangle(t.map(|i| corners[i]), [Vec3::Y; 3], Some(t.map(|i| uv[i])));
        soup.tri_material.push(0);
        soup.tri_object.push(0);
    }
    soup.lights = vec![Light {
        name: "sun".into(),
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: Vec3::new(0.3, -1.0, 0.5).normalize(),
        color: Vec3::ONE,
        intensity: 1.0,
        range: 0.0,
        attenuation: formats::Attenuation::BuiltIn,
        shadows: Shadows::None,
        shadow_radius: 0.0,
        shadow_strength: 1.0,
        culling_mask: u32::MAX,
    }];
    soup.camera = look(Vec3::new(0.0, 1.0, -1.0), Vec3::new(0.0, 0.0, 8.0), 50.0);
    soup.environment = environment(Vec3::new(0.35, 0.45, 0.6), Vec3::splat(0.1));
    soup.seal();
    Scene {
        name: "checkerboard".into(),
        soup,
    }
}

/// `scene` with every material textured by a 512×512 checker (8-texel squares) projected
/// from above (uv = (x, z) / 2 m): what textures cost on real geometry, where shadow and
/// mirror rays dilute the lookups.
pub fn with_checker(scene: &Scene) -> Scene {
    let mut soup = scene.soup.clone();
    soup.textures = vec![checker_texture(512, 8)];
    for m in &mut soup.materials {
        m.albedo_map = Some(TextureRef {
            texture: 0,
            tiling: Tiling::default(),
        });
    }
    soup.uvs = soup
        .positions
        .iter()
        .map(|p| Vec2::new(p.x, p.z) / 2.0)
        .collect();
    Scene {
        name: format!("{}-textured", scene.name),
        soup,
    }
}

/// `scene` lit by a sun with soft shadows over a cone `cone` degrees across instead of its
/// own lights: at 4° the widest light the renderer's soft-shadow rim probe is asked about,
/// so the sweep measures what the probe costs in accuracy where it can cost most.
pub fn with_sun(scene: &Scene, name: &str, cone: f32) -> Scene {
    let mut soup = scene.soup.clone();
    soup.lights = vec![Light {
        name: "sun".into(),
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: Vec3::new(-0.4, -1.0, 0.3).normalize(),
        color: Vec3::ONE,
        intensity: 1.0,
        range: 0.0,
        attenuation: formats::Attenuation::BuiltIn,
        shadows: Shadows::Soft,
        shadow_radius: cone,
        shadow_strength: 1.0,
        culling_mask: u32::MAX,
    }];
    Scene {
        name: name.into(),
        soup,
    }
}

/// A tiny scene for tests: a mirror floor, a diffuse box-less wall and a floating
/// triangle casting a soft shadow from a point light.
pub fn tiny() -> Scene {
    let mut soup = Soup::empty();
    soup.materials = vec![
        material("mirror", Vec3::splat(0.7), 1.0, 0.8),
        material("red", Vec3::new(0.8, 0.2, 0.2), 0.0, 0.5),
    ];
    soup.objects = vec![Object::new("floor", "tiny"), Object::new("blocker", "tiny")];
    floor(&mut soup, 2.0, 0, 0);
    // A wall facing the camera (−Z), behind the blocker.
    quad(
        &mut soup,
        [
            Vec3::new(-2.0, 0.0, 1.0),
            Vec3::new(-2.0, 2.0, 1.0),
            Vec3::new(2.0, 2.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
        ],
        1,
        1,
    );
    let t = [
        Vec3::new(-0.5, 0.5, 0.0),
        Vec3::new(0.0, 1.2, 0.0),
        Vec3::new(0.5, 0.5, 0.0),
    ];
    soup.push_triangle(t, [Vec3::NEG_Z; 3], None);
    soup.tri_material.push(1);
    soup.tri_object.push(1);
    soup.lights = vec![point_light("key", Vec3::new(0.3, 2.0, -1.5), 4.0, 0.5)];
    soup.camera = look(Vec3::new(0.0, 1.0, -3.0), Vec3::new(0.0, 0.6, 0.5), 50.0);
    soup.environment = environment(Vec3::new(0.2, 0.3, 0.5), Vec3::splat(0.05));
    soup.seal();
    Scene {
        name: "tiny".into(),
        soup,
    }
}
