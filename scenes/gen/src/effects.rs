//! One small project per rendering effect (what `just gallery` renders), built from Unity's
//! built-in primitives: each isolates one thing the renderer must get right.

use crate::material::{write_material, write_surface, MatDesc, Surface};
use crate::meta;
use crate::project::Project;
use crate::unity::{
    self, Ambient, Body, CameraDesc, FogDesc, LightDesc, LightType, MeshRef, Object, SceneDesc,
    Xform,
};
use std::collections::BTreeMap;

/// A project under construction: its materials by name, and the objects of its one scene.
/// Public so that end-to-end tests can write small Unity projects of their own.
pub struct Builder {
    project: Project,
    mats: BTreeMap<&'static str, String>,
    objects: Vec<Object>,
    fog: Option<FogDesc>,
    skybox: Option<String>,
    reflection: f32,
}

impl Builder {
    pub fn new(name: &str, looks: &[MatDesc]) -> Self {
        let mut project = Project::new(name);
        let mut mats = BTreeMap::new();
        for m in looks {
            let path = format!("Assets/Materials/{}.mat", m.name);
            mats.insert(
                m.name,
                project.add_asset(&path, write_material(m), meta::material),
            );
        }
        Builder {
            project,
            mats,
            objects: Vec::new(),
            fog: None,
            skybox: None,
            reflection: 1.0,
        }
    }

    /// Set the environment reflection's intensity of the scenes written next (0: surfaces
    /// reflect no sky, as a scene whose pixels follow from its lights alone needs).
    pub fn reflection(&mut self, intensity: f32) -> &mut Self {
        self.reflection = intensity;
        self
    }

    /// Turn on RenderSettings fog in the scene written next.
    pub fn fog(&mut self, fog: FogDesc) -> &mut Self {
        self.fog = Some(fog);
        self
    }

    /// Add the material file `yaml` at `path` and name it as RenderSettings' skybox.
    pub fn skybox(&mut self, path: &str, yaml: String) -> &mut Self {
        let guid = self.project.add_asset(path, yaml, meta::material);
        self.skybox = Some(guid);
        self
    }

    /// Add a look that draws with a texture or alpha.
    pub fn look(&mut self, m: &MatDesc, surface: &Surface) -> &mut Self {
        let path = format!("Assets/Materials/{}.mat", m.name);
        let guid = self
            .project
            .add_asset(&path, write_surface(m, surface), meta::material);
        self.mats.insert(m.name, guid);
        self
    }

    /// Add an image file at `path` with its TextureImporter `.meta`; returns its GUID.
    pub fn texture(&mut self, path: &str, bytes: Vec<u8>, import: &meta::TextureImport) -> String {
        let guid = self.project.guid(path);
        self.project.files.insert(path.to_string(), bytes);
        self.project
            .add(&format!("{path}.meta"), meta::texture(&guid, import));
        guid
    }

    /// Add the file `bytes` at `path` with the `.meta` `meta_of` makes; returns its GUID.
    pub fn asset(&mut self, path: &str, bytes: Vec<u8>, meta_of: fn(&str) -> String) -> String {
        self.project.add_binary_asset(path, bytes, meta_of)
    }

    /// Add an object of any kind to the scene.
    pub fn object(&mut self, object: Object) -> &mut Self {
        self.objects.push(object);
        self
    }

    /// The GUID an asset at `path` of this project gets.
    pub fn guid(&self, path: &str) -> String {
        self.project.guid(path)
    }

    /// Write the objects added so far as `Assets/Scenes/<scene_name>.unity` and start the
    /// next scene of the same project.
    pub fn scene(&mut self, scene_name: &str, ambient: Ambient) -> &mut Self {
        let path = format!("Assets/Scenes/{scene_name}.unity");
        let key = format!("{}/{scene_name}", self.project.name);
        let scene = SceneDesc {
            ambient,
            fog: self.fog.take(),
            skybox: self.skybox.clone(),
            reflection: self.reflection,
            objects: std::mem::take(&mut self.objects),
        };
        self.project
            .add_asset(&path, unity::write_scene(&key, &scene), meta::scene);
        self
    }

    /// The project with every scene written by [`Builder::scene`].
    pub fn done(self) -> Project {
        self.project.finish()
    }

    pub fn camera(&mut self, xform: Xform, desc: CameraDesc) -> &mut Self {
        self.objects.push(Object {
            name: "Main Camera".into(),
            xform,
            body: Body::Camera(desc),
        });
        self
    }

    pub fn light(&mut self, name: &str, xform: Xform, desc: LightDesc) -> &mut Self {
        self.objects.push(Object {
            name: name.into(),
            xform,
            body: Body::Light(desc),
        });
        self
    }

    pub fn mesh(&mut self, name: &str, builtin: i64, look: &str, xform: Xform) -> &mut Self {
        let guid = self.mats[look].clone();
        self.objects.push(Object {
            name: name.into(),
            xform,
            body: Body::Mesh {
                mesh: MeshRef::Builtin(builtin),
                materials: vec![guid],
            },
        });
        self
    }

    /// Write the scene to `Assets/Scenes/<scene_name>.unity` and complete the project.
    pub fn finish(mut self, scene_name: &str, ambient: Ambient) -> Project {
        let path = format!("Assets/Scenes/{scene_name}.unity");
        let key = format!("{}/{scene_name}", self.project.name);
        let scene = SceneDesc {
            ambient,
            fog: self.fog.take(),
            skybox: self.skybox.clone(),
            reflection: self.reflection,
            objects: std::mem::take(&mut self.objects),
        };
        self.project
            .add_asset(&path, unity::write_scene(&key, &scene), meta::scene);
        self.project.finish()
    }
}

const DARK_BLUE: [f32; 3] = [0.05, 0.07, 0.12];
const NO_AMBIENT: Ambient = Ambient::Flat([0.0, 0.0, 0.0]);

fn camera_desc() -> CameraDesc {
    CameraDesc {
        background: DARK_BLUE,
        ..CameraDesc::default()
    }
}

fn basic_looks() -> Vec<MatDesc> {
    vec![
        MatDesc::matte("Grey", [0.75, 0.75, 0.75]),
        MatDesc::matte("Red", [0.85, 0.15, 0.1]),
        MatDesc::matte("Blue", [0.15, 0.3, 0.85]),
    ]
}

/// A 10 m plane, a cube and a sphere, seen from the front and above: the stage most
/// effect scenes share.
fn stage(b: &mut Builder) -> &mut Builder {
    b.camera(
        Xform::at(0.0, 3.0, -7.0).euler(18.0, 0.0, 0.0),
        camera_desc(),
    )
    .mesh("Ground", unity::PLANE, "Grey", Xform::at(0.0, 0.0, 0.0))
    .mesh(
        "Cube",
        unity::CUBE,
        "Red",
        Xform::at(-1.0, 0.5, 0.0).euler(0.0, 30.0, 0.0),
    )
    .mesh("Sphere", unity::SPHERE, "Blue", Xform::at(1.2, 0.5, 0.5))
}

fn point(color: [f32; 3], intensity: f32, range: f32, shadows: u8) -> LightDesc {
    LightDesc {
        shadows,
        ..LightDesc::point(color, intensity, range)
    }
}

/// Hard shadows from one point light.
pub fn shadows_hard() -> Project {
    let mut b = Builder::new("shadows-hard", &basic_looks());
    stage(&mut b).light(
        "Point Light",
        Xform::at(-2.0, 4.0, -1.5),
        point([1.0, 1.0, 1.0], 1.5, 20.0, 1),
    );
    b.finish("ShadowsHard", NO_AMBIENT)
}

/// Soft shadows: the same light with shadow type 2 and a 0.5 m emitter radius.
pub fn shadows_soft() -> Project {
    let mut b = Builder::new("shadows-soft", &basic_looks());
    stage(&mut b).light(
        "Point Light",
        Xform::at(-2.0, 4.0, -1.5),
        LightDesc {
            shadow_radius: 0.5,
            ..point([1.0, 1.0, 1.0], 1.5, 20.0, 2)
        },
    );
    b.finish("ShadowsSoft", NO_AMBIENT)
}

/// A spot light looking down at the cube: a 50° cone with a 30° fully lit core.
pub fn spot() -> Project {
    let mut b = Builder::new("spot", &basic_looks());
    stage(&mut b).light(
        "Spot Light",
        Xform::at(-0.5, 5.0, -1.0).euler(80.0, 0.0, 0.0),
        LightDesc {
            kind: LightType::Spot {
                angle: 50.0,
                inner_angle: 30.0,
            },
            ..point([1.0, 0.95, 0.85], 2.0, 15.0, 1)
        },
    );
    b.finish("Spot", NO_AMBIENT)
}

/// A directional light (sun) at 50° elevation: shading by the cosine, parallel shadows.
pub fn directional() -> Project {
    let mut b = Builder::new("directional", &basic_looks());
    stage(&mut b).light(
        "Directional Light",
        Xform::at(0.0, 3.0, 0.0).euler(50.0, -30.0, 0.0),
        LightDesc {
            kind: LightType::Directional,
            ..point([1.0, 0.96, 0.84], 1.0, 10.0, 1)
        },
    );
    b.finish("Directional", NO_AMBIENT)
}

/// Two mirrors facing each other with a sphere between them: the corridor of images
/// ends where the reflection depth does.
pub fn reflection_depth() -> Project {
    let mut looks = basic_looks();
    looks.push(MatDesc::mirror("Mirror"));
    let mut b = Builder::new("reflection-depth", &looks);
    b.camera(
        Xform::at(-1.2, 1.6, -3.2).euler(8.0, 30.0, 0.0),
        camera_desc(),
    )
    .mesh("Ground", unity::PLANE, "Grey", Xform::at(0.0, 0.0, 0.0))
    .mesh(
        "Mirror Left",
        unity::CUBE,
        "Mirror",
        Xform::at(-2.0, 1.5, 0.0).scale(0.1, 3.0, 4.0),
    )
    .mesh(
        "Mirror Right",
        unity::CUBE,
        "Mirror",
        Xform::at(2.0, 1.5, 0.0).scale(0.1, 3.0, 4.0),
    )
    .mesh(
        "Sphere",
        unity::SPHERE,
        "Red",
        Xform::at(0.0, 0.8, 0.5).uniform(0.8),
    )
    .mesh(
        "Cube",
        unity::CUBE,
        "Blue",
        Xform::at(0.6, 0.25, -0.6)
            .euler(0.0, 20.0, 0.0)
            .uniform(0.5),
    )
    .light(
        "Point Light",
        Xform::at(0.0, 4.0, -1.5),
        point([1.0, 1.0, 1.0], 1.3, 20.0, 1),
    );
    b.finish("ReflectionDepth", NO_AMBIENT)
}

/// No lights at all: only trilight ambient (sky above, equator at the sides, ground
/// below) shades the objects by their normals.
pub fn ambient() -> Project {
    let looks = vec![
        MatDesc::matte("White", [1.0, 1.0, 1.0]),
        MatDesc::matte("Grey", [0.75, 0.75, 0.75]),
    ];
    let mut b = Builder::new("ambient", &looks);
    b.camera(
        Xform::at(0.0, 3.0, -7.0).euler(18.0, 0.0, 0.0),
        camera_desc(),
    )
    .mesh("Ground", unity::PLANE, "Grey", Xform::at(0.0, 0.0, 0.0))
    .mesh(
        "Cube",
        unity::CUBE,
        "White",
        Xform::at(-1.2, 0.5, 0.0).euler(0.0, 30.0, 0.0),
    )
    .mesh(
        "Sphere",
        unity::SPHERE,
        "White",
        Xform::at(1.2, 0.75, 0.0).uniform(1.5),
    );
    b.finish(
        "Ambient",
        Ambient::Trilight([0.55, 0.7, 1.0], [0.5, 0.45, 0.4], [0.25, 0.2, 0.15]),
    )
}

/// Self-lit objects in a dim room: emission shows at full strength whatever the light.
pub fn emission() -> Project {
    let looks = vec![
        MatDesc::matte("Grey", [0.75, 0.75, 0.75]),
        MatDesc {
            emission: Some([1.0, 0.55, 0.1]),
            ..MatDesc::matte("GlowOrange", [1.0, 0.55, 0.1])
        },
        MatDesc {
            emission: Some([0.1, 0.8, 1.0]),
            ..MatDesc::matte("GlowCyan", [0.1, 0.8, 1.0])
        },
    ];
    let mut b = Builder::new("emission", &looks);
    b.camera(
        Xform::at(0.0, 3.0, -7.0).euler(18.0, 0.0, 0.0),
        CameraDesc {
            background: [0.0, 0.0, 0.0],
            ..CameraDesc::default()
        },
    )
    .mesh("Ground", unity::PLANE, "Grey", Xform::at(0.0, 0.0, 0.0))
    .mesh(
        "Glowing Sphere",
        unity::SPHERE,
        "GlowOrange",
        Xform::at(-1.0, 0.6, 0.0).uniform(1.2),
    )
    .mesh(
        "Glowing Cube",
        unity::CUBE,
        "GlowCyan",
        Xform::at(1.3, 0.5, 0.3).euler(0.0, 45.0, 0.0),
    )
    .light(
        "Dim Light",
        Xform::at(0.0, 4.0, -3.0),
        point([1.0, 1.0, 1.0], 0.3, 15.0, 1),
    );
    b.finish("Emission", NO_AMBIENT)
}

/// An orthographic camera (half-height 3 m) looking down at 45° over a row of objects:
/// equal objects at different depths keep the same size.
pub fn orthographic() -> Project {
    let mut b = Builder::new("orthographic", &basic_looks());
    b.camera(
        Xform::at(0.0, 6.0, -6.0).euler(45.0, 0.0, 0.0),
        CameraDesc {
            orthographic: Some(3.0),
            ..camera_desc()
        },
    )
    .mesh("Ground", unity::PLANE, "Grey", Xform::at(0.0, 0.0, 0.0));
    for (k, z) in [-2.0f32, 0.0, 2.0].into_iter().enumerate() {
        let x = -1.5 + 1.5 * k as f32;
        b.mesh(
            &format!("Cube ({k})"),
            unity::CUBE,
            "Red",
            Xform::at(x, 0.5, z),
        );
        b.mesh(
            &format!("Sphere ({k})"),
            unity::SPHERE,
            "Blue",
            Xform::at(x + 0.75, 0.5, z - 1.0),
        );
    }
    b.light(
        "Point Light",
        Xform::at(-2.0, 5.0, -2.0),
        point([1.0, 1.0, 1.0], 1.5, 25.0, 1),
    );
    b.finish("Orthographic", NO_AMBIENT)
}

/// The fog colour, also the camera's background: the sky Unity leaves unfogged matches
/// the distance, as scenes with fog usually set it.
const FOG_GREY: [f32; 3] = [0.62, 0.66, 0.72];

/// A row of pillars walking away from the camera into exponential squared fog (density
/// 0.04): each farther pillar keeps less of its own colour.
pub fn fog() -> Project {
    let mut b = Builder::new("fog", &basic_looks());
    b.camera(
        Xform::at(0.0, 1.6, -6.0).euler(4.0, 0.0, 0.0),
        CameraDesc {
            background: FOG_GREY,
            ..CameraDesc::default()
        },
    )
    .mesh(
        "Ground",
        unity::PLANE,
        "Grey",
        Xform::at(0.0, 0.0, 40.0).scale(4.0, 1.0, 10.0),
    );
    for i in 0..6 {
        let (x, look) = if i % 2 == 0 {
            (-1.5, "Red")
        } else {
            (1.5, "Blue")
        };
        let at = Xform::at(x, 1.5, 8.0 * i as f32).scale(1.0, 3.0, 1.0);
        b.mesh(&format!("Pillar {i}"), unity::CUBE, look, at);
    }
    b.light(
        "Directional Light",
        Xform::at(0.0, 3.0, 0.0).euler(50.0, -30.0, 0.0),
        LightDesc {
            kind: LightType::Directional,
            ..point([1.0, 0.96, 0.84], 1.0, 10.0, 1)
        },
    )
    .fog(FogDesc {
        mode: 3,
        colour: FOG_GREY,
        density: 0.04,
        start: 0.0,
        end: 300.0,
    });
    b.finish("Fog", Ambient::Flat([0.2, 0.2, 0.22]))
}

/// Every effect project, in gallery order.
pub fn all() -> Vec<Project> {
    vec![
        shadows_hard(),
        shadows_soft(),
        spot(),
        directional(),
        reflection_depth(),
        ambient(),
        emission(),
        orthographic(),
        fog(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_text(p: &Project) -> String {
        let (_, bytes) = p
            .files
            .iter()
            .find(|(k, _)| k.ends_with(".unity"))
            .expect("one scene per project");
        String::from_utf8(bytes.clone()).unwrap()
    }

    #[test]
    fn each_scene_sets_its_effect() {
        assert!(scene_text(&shadows_hard()).contains("  m_Shadows:\n    m_Type: 1\n"));
        let soft = scene_text(&shadows_soft());
        assert!(
            soft.contains("  m_Shadows:\n    m_Type: 2\n")
                && soft.contains("  m_ShadowRadius: 0.5\n")
        );
        let spot = scene_text(&spot());
        assert!(spot.contains("  m_Type: 0\n") && spot.contains("  m_SpotAngle: 50\n"));
        assert!(spot.contains("  m_InnerSpotAngle: 30\n"));
        assert!(scene_text(&directional()).contains("  m_Type: 1\n  m_Shape: 0\n"));
        let amb = scene_text(&ambient());
        assert!(amb.contains("  m_AmbientMode: 1\n") && !amb.contains("--- !u!108 "));
        assert!(scene_text(&orthographic()).contains("  orthographic: 1\n  orthographic size: 3\n"));
        let emission = emission();
        assert!(emission
            .files
            .iter()
            .any(|(k, v)| k.ends_with(".mat")
                && String::from_utf8_lossy(v).contains("  - _EMISSION\n")));
        let fog = scene_text(&fog());
        assert!(fog.contains("  m_Fog: 1\n") && fog.contains("  m_FogMode: 3\n"));
        assert!(fog.contains("  m_FogDensity: 0.04\n"));
        assert!(scene_text(&ambient()).contains("  m_Fog: 0\n"));
        let mirrors = scene_text(&reflection_depth());
        assert_eq!(mirrors.matches("  m_Name: Mirror ").count(), 2);
    }
}
