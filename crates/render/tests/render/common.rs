//! Small scenes built in code for the renderer's tests: quads, boxes, lights, cameras.

use formats::texture::{Filter, Texture, Wrap};
use formats::{
    Alpha, Camera, Cull, KdFile, Light, LightKind, Material, Object, Projection, Shadows, Soup,
};
use glam::{Vec2, Vec3};
use render::{render_scene, Plan, RenderOptions, Rendered};

pub struct SceneBuilder {
    pub soup: Soup,
}

impl Default for SceneBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl SceneBuilder {
    /// An empty scene: Unity's default camera, black background, no ambient.
    pub fn new() -> Self {
        SceneBuilder {
            soup: Soup::empty(),
        }
    }

    pub fn material(&mut self, m: Material) -> u32 {
        self.soup.materials.push(m);
        self.soup.materials.len() as u32 - 1
    }

    /// A grey diffuse material with albedo `c`.
    pub fn diffuse(&mut self, c: Vec3) -> u32 {
        self.material(diffuse(c))
    }

    /// A quad with corners `o`, `o + u`, `o + u + v`, `o + v`; its front (and normal) is u × v.
    /// Its UVs run from (0, 0) at `o` to (1, 1) at `o + u + v`, u along `u`.
    pub fn quad(&mut self, name: &str, o: Vec3, u: Vec3, v: Vec3, material: u32) -> u32 {
        self.quad_uv(name, o, u, v, material, [Vec2::ZERO, Vec2::ONE])
    }

    /// [`SceneBuilder::quad`] with UVs from `uv[0]` at `o` to `uv[1]` at `o + u + v`.
    pub fn quad_uv(
        &mut self,
        name: &str,
        o: Vec3,
        u: Vec3,
        v: Vec3,
        material: u32,
        uv: [Vec2; 2],
    ) -> u32 {
        let obj = self.soup.objects.len() as u32;
        self.soup.objects.push(Object::new(name, "test"));
        let n = u.cross(v).normalize();
        let (a, b) = (uv[0], uv[1]);
        let corner = [a, Vec2::new(b.x, a.y), b, Vec2::new(a.x, b.y)];
        let p = [o, o + u, o + u + v, o + v];
        for t in [[0, 1, 2], [0, 2, 3]] {
            self.soup
                .push_triangle(t.map(|i| p[i]), [n; 3], Some(t.map(|i| corner[i])));
            self.soup.tri_material.push(material);
            self.soup.tri_object.push(obj);
        }
        obj
    }

    /// Add a texture; its index for a material's `albedo_map`.
    pub fn texture(&mut self, t: Texture) -> u32 {
        self.soup.textures.push(t);
        self.soup.textures.len() as u32 - 1
    }

    /// A horizontal square floor at height `y`, centred on (cx, cz), facing +Y.
    pub fn floor(&mut self, y: f32, cx: f32, cz: f32, size: f32, material: u32) -> u32 {
        let h = size / 2.0;
        self.quad(
            "floor",
            Vec3::new(cx - h, y, cz - h),
            Vec3::new(0.0, 0.0, size),
            Vec3::new(size, 0.0, 0.0),
            material,
        )
    }

    /// An axis-aligned box from `lo` to `hi`, faces pointing outwards.
    pub fn cube(&mut self, name: &str, lo: Vec3, hi: Vec3, material: u32) -> u32 {
        let obj = self.soup.objects.len() as u32;
        self.soup.objects.push(Object::new(name, "test"));
        let d = hi - lo;
        let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        let faces = [
            (lo, x, z),     // bottom, −Y
            (lo + y, z, x), // top, +Y
            (lo, y, x),     // −Z
            (lo + z, x, y), // +Z
            (lo, z, y),     // −X
            (lo + x, y, z), // +X
        ];
        for (o, u, v) in faces {
            let n = u.cross(v).normalize();
            for t in [[o, o + u, o + u + v], [o, o + u + v, o + v]] {
                self.soup.push_triangle(t, [n; 3], Some([Vec2::ZERO; 3]));
                self.soup.tri_material.push(material);
                self.soup.tri_object.push(obj);
            }
        }
        obj
    }

    pub fn light(&mut self, l: Light) {
        self.soup.lights.push(l);
    }

    pub fn camera(&mut self, c: Camera) {
        self.soup.camera = c;
    }

    /// Seal and compile the scene; a scene without albedo or normal maps keeps no UVs, as unity2soup
    /// writes it.
    pub fn build(mut self) -> (Soup, KdFile) {
        if !self.soup.materials.iter().any(Material::reads_uvs) {
            self.soup.uvs.clear();
        }
        self.soup.seal();
        self.soup.validate().expect("test scene is valid");
        let kd = kdtree::build(
            &self.soup.triangle_positions(),
            &formats::BuildParams::default(),
            self.soup.geometry_hash,
        );
        (self.soup, kd)
    }
}

/// Test materials are two-sided (`Cull::None`) so a scene sees both faces unless a test asks
/// for culling, and have Specular Highlights off, so that a lit point shows the diffuse
/// formula alone (highlights have tests of their own).
pub fn diffuse(c: Vec3) -> Material {
    Material {
        name: "diffuse".into(),
        source: "test".into(),
        color: c,
        metallic: 0.0,
        smoothness: 0.0,
        smoothness_in_alpha: false,
        pbs: false,
        highlights: false,
        reflections: false,
        reflectivity: None,
        emission: Vec3::ZERO,
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

pub fn mirror(reflectivity: f32) -> Material {
    Material {
        name: "mirror".into(),
        source: "test".into(),
        color: Vec3::ONE,
        metallic: 1.0,
        smoothness: 1.0,
        smoothness_in_alpha: false,
        pbs: false,
        highlights: false,
        reflections: false,
        reflectivity: Some(reflectivity),
        emission: Vec3::ZERO,
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

pub fn emissive(e: Vec3) -> Material {
    Material {
        name: "emissive".into(),
        source: "test".into(),
        color: Vec3::ZERO,
        metallic: 0.0,
        smoothness: 0.0,
        smoothness_in_alpha: false,
        pbs: false,
        highlights: false,
        reflections: false,
        reflectivity: None,
        emission: e,
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

pub fn point_light(position: Vec3, intensity: f32, range: f32, shadows: Shadows) -> Light {
    Light {
        name: "point".into(),
        kind: LightKind::Point,
        position,
        direction: -Vec3::Y,
        color: Vec3::ONE,
        intensity,
        range,
        attenuation: formats::Attenuation::BuiltIn,
        shadows,
        shadow_radius: 0.0,
        shadow_strength: 1.0,
        culling_mask: u32::MAX,
    }
}

pub fn spot_light(
    position: Vec3,
    direction: Vec3,
    angle: f32,
    inner_angle: f32,
    range: f32,
) -> Light {
    Light {
        name: "spot".into(),
        kind: LightKind::Spot { angle, inner_angle },
        position,
        direction: direction.normalize(),
        color: Vec3::ONE,
        intensity: 1.0,
        range,
        attenuation: formats::Attenuation::BuiltIn,
        shadows: Shadows::None,
        shadow_radius: 0.0,
        shadow_strength: 1.0,
        culling_mask: u32::MAX,
    }
}

pub fn directional_light(direction: Vec3, intensity: f32, shadows: Shadows) -> Light {
    Light {
        name: "sun".into(),
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: direction.normalize(),
        color: Vec3::ONE,
        intensity,
        range: 0.0,
        attenuation: formats::Attenuation::BuiltIn,
        shadows,
        shadow_radius: 0.0,
        shadow_strength: 1.0,
        culling_mask: u32::MAX,
    }
}

/// A `w`×`h` texture of linear 8-bit RGBA texels, bottom row first, point-filtered.
pub fn texture(w: u32, h: u32, texels: &[[u8; 4]], wrap: Wrap) -> Texture {
    Texture {
        source: "test.png".into(),
        width: w,
        height: h,
        texels: texels.concat(),
        srgb: false,
        wrap_u: wrap,
        wrap_v: wrap,
        filter: Filter::Point,
        mipmaps: true,
    }
}

/// An orthographic camera at `position` looking straight down (−Y), image up = +Z, so
/// image right = forward × up = −X.
pub fn top_down_camera(position: Vec3, half_height: f32) -> Camera {
    Camera {
        name: "top".into(),
        position,
        forward: -Vec3::Y,
        up: Vec3::Z,
        projection: Projection::Orthographic { half_height },
        near: 0.0,
        far: f32::INFINITY,
    }
}

/// The world point on the plane y = `y` seen at the centre of pixel (px, py) by an
/// orthographic camera (independent of the renderer's camera code).
pub fn ortho_point(cam: &Camera, width: u32, height: u32, px: u32, py: u32, y: f32) -> Vec3 {
    let Projection::Orthographic { half_height } = cam.projection else {
        panic!("orthographic camera expected")
    };
    let aspect = width as f32 / height as f32;
    let sx = ((px as f32 + 0.5) / width as f32 * 2.0 - 1.0) * half_height * aspect;
    let sy = (1.0 - (py as f32 + 0.5) / height as f32 * 2.0) * half_height;
    let on_plane = cam.position + cam.right() * sx + cam.up * sy;
    Vec3::new(on_plane.x, y, on_plane.z)
}

pub fn opts(width: u32, height: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        ..RenderOptions::default()
    }
}

/// Render in-process and check that no pixel or AOV holds NaN or Inf.
pub fn render(soup: &Soup, kd: &KdFile, opts: &RenderOptions) -> (Rendered, Plan) {
    let (out, plan) = render_scene(soup, kd, opts).expect("render succeeds");
    assert_eq!(out.frame.non_finite(), 0, "the image holds NaN or Inf");
    (out, plan)
}

/// `opts` rendered on one thread with tiles of 1 pixel (no 2×2 blocks), 5 (blocks, and a
/// last row and column alone) and 32: asserts the same frame and counts, returns the first.
pub fn render_alike_at_tiles(soup: &Soup, kd: &KdFile, opts: &RenderOptions) -> Rendered {
    let mut o = opts.clone();
    o.threads = Some(1);
    let runs = [1, 5, 32].map(|tile| {
        o.tile = tile;
        render(soup, kd, &o).0
    });
    let [first, rest @ ..] = runs;
    for r in &rest {
        assert_eq!(r.frame, first.frame);
        assert_eq!(r.counts, first.counts);
    }
    first
}

/// Relative difference, per channel, of `got` from `want` is within `tol`.
pub fn assert_close(got: Vec3, want: Vec3, tol: f32, what: &str) {
    for c in 0..3 {
        let (g, w) = (got[c], want[c]);
        let err = (g - w).abs() / w.abs().max(1e-6);
        assert!(
            err <= tol || (g - w).abs() <= 1e-6,
            "{what}: got {got}, want {want} (channel {c} off by {:.3}%)",
            err * 100.0
        );
    }
}

/// Unity's falloff, written out independently of the renderer.
pub fn unity_falloff(d: f32, range: f32) -> f32 {
    let x = d / range;
    if x >= 1.0 {
        return 0.0;
    }
    let fade = if x <= 0.8 { 1.0 } else { (1.0 - x) / 0.2 };
    fade / (1.0 + 25.0 * x * x)
}
