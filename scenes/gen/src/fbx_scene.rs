//! The FBX scale test: `models` distinct binary FBX models of 65,536 triangles each (four
//! parts, wavy tori of different proportions, half written as quads and half as
//! triangles), every model placed twice as a prefab instance on a grid, with a camera
//! and a sun. Not bundled: `scenegen DIR --fbx MODELS` writes it (16 models: 1,048,576
//! triangles in the files, twice that in the scene; `--deflate` compresses the arrays as
//! exporters do).

use crate::fbx::{self, Part};
use crate::material::{write_material, MatDesc};
use crate::meta;
use crate::project::Project;
use crate::unity::{
    self, Ambient, Body, CameraDesc, LightDesc, LightType, Object, SceneDesc, Xform,
};
use glam::Vec3;
use std::f32::consts::TAU;

pub const NAME: &str = "fbxlarge";
pub const SCENE_PATH: &str = "Assets/Scenes/FbxLarge.unity";
/// Parts per model, and the torus grid of each: 128 × 64 quads, 16,384 triangles.
pub const PARTS: usize = 4;
const RING: u32 = 128;
const TUBE: u32 = 64;
pub const TRIANGLES_PER_MODEL: usize = PARTS * 2 * (RING * TUBE) as usize;
// The default scene (16 models) is the million-triangle test.
const _: () = assert!(16 * TRIANGLES_PER_MODEL >= 1_000_000);
/// Prefab instances of each model, unless told otherwise.
pub const INSTANCES: usize = 2;
/// Grid spacing of the instances (a model spans about 5 m).
const SPACING: f32 = 7.0;

/// Part `j` of model `k`: a torus whose radii and surface ripples depend on both, so no
/// two parts in the project are alike; odd parts are written as triangles.
pub fn part(k: usize, j: usize) -> Part {
    let major = 0.8 + 0.05 * ((k * 7 + j * 3) % 9) as f32;
    let minor = 0.25 + 0.03 * ((k + j * 5) % 5) as f32;
    let waves = 3.0 + ((k + j) % 6) as f32;
    let ripple = 0.04 + 0.01 * (j % 3) as f32;
    let at = |u: f32, v: f32| {
        let r = minor * (1.0 + ripple * (waves * u).sin() * (2.0 * v).cos());
        let (su, cu) = (TAU * u).sin_cos();
        let (sv, cv) = (TAU * v).sin_cos();
        // Lying flat: the ring in the XZ plane, lifted to stand on y = 0.
        Vec3::new(
            (major + r * cv) * cu,
            minor * 1.2 + r * sv,
            (major + r * cv) * su,
        )
    };
    let mut positions = Vec::with_capacity((RING * TUBE) as usize);
    for i in 0..RING {
        for t in 0..TUBE {
            positions.push(at(i as f32 / RING as f32, t as f32 / TUBE as f32));
        }
    }
    let index = |i: u32, t: u32| (i % RING) * TUBE + t % TUBE;
    let mut polygons = Vec::with_capacity((2 * RING * TUBE) as usize);
    for i in 0..RING {
        for t in 0..TUBE {
            // Counter-clockwise seen from outside the tube.
            let q = [
                index(i, t),
                index(i, t + 1),
                index(i + 1, t + 1),
                index(i + 1, t),
            ];
            if j.is_multiple_of(2) {
                polygons.push(q.to_vec());
            } else {
                polygons.push(vec![q[0], q[1], q[2]]);
                polygons.push(vec![q[0], q[2], q[3]]);
            }
        }
    }
    let normals = vertex_normals(&positions, &polygons);
    // The four parts side by side, 2.5 m apart.
    let translation = Vec3::new(
        if j.is_multiple_of(2) { -1.25 } else { 1.25 },
        0.0,
        if j < 2 { -1.25 } else { 1.25 },
    );
    Part {
        name: format!("Torus{k}_{j}"),
        translation,
        positions,
        normals,
        polygons,
    }
}

/// Area-weighted face normals summed at each vertex (a polygon's normal from its
/// corners' cross products, so quads need not be planar).
fn vertex_normals(positions: &[Vec3], polygons: &[Vec<u32>]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for poly in polygons {
        let c = poly.iter().map(|&i| positions[i as usize]);
        let mut n = Vec3::ZERO;
        for (a, b) in c.clone().zip(c.cycle().skip(1)) {
            n += a.cross(b);
        }
        for &i in poly {
            acc[i as usize] += n;
        }
    }
    acc.into_iter().map(|n| n.normalize_or_zero()).collect()
}

/// The FBX file of model `k`, its arrays deflated when `compress` (as exporters write
/// them) or raw.
pub fn model_file(k: usize, compress: bool) -> Vec<u8> {
    let parts: Vec<Part> = (0..PARTS).map(|j| part(k, j)).collect();
    let hue = k as f32 * 0.618_034 % 1.0;
    let color = [
        0.35 + 0.6 * (TAU * hue).cos().abs(),
        0.35 + 0.6 * (TAU * (hue + 0.33)).cos().abs(),
        0.35 + 0.6 * (TAU * (hue + 0.66)).cos().abs(),
    ];
    fbx::write(&fbx::File {
        parts: &parts,
        material: &format!("Torus{k}"),
        color,
        compress,
    })
}

/// The project with `models` (at least 1) distinct FBX models, compressed or raw, each
/// placed `instances` times (at least 1).
pub fn project(models: usize, instances: usize, compress: bool) -> Project {
    let models = models.max(1);
    let mut p = Project::new(NAME);
    let floor = p.add_asset(
        "Assets/Materials/Floor.mat",
        write_material(&MatDesc::matte("Floor", [0.55, 0.55, 0.58])),
        meta::material,
    );
    let guids: Vec<String> = (0..models)
        .map(|k| {
            let path = format!("Assets/Models/Torus{k}.fbx");
            p.add_binary_asset(&path, model_file(k, compress), meta::model)
        })
        .collect();
    let count = models * instances.max(1);
    let side = (count as f32).sqrt().ceil() as usize;
    let width = SPACING * side as f32;
    let centre = |i: usize| (i as f32 - (side as f32 - 1.0) / 2.0) * SPACING;
    let mut objects = vec![
        Object {
            name: "Main Camera".into(),
            xform: Xform::at(0.0, 0.45 * width, -0.8 * width).euler(30.0, 0.0, 0.0),
            body: Body::Camera(CameraDesc {
                background: [0.05, 0.07, 0.12],
                ..CameraDesc::default()
            }),
        },
        Object {
            name: "Sun".into(),
            xform: Xform::at(0.0, 10.0, 0.0).euler(50.0, -30.0, 0.0),
            body: Body::Light(LightDesc {
                kind: LightType::Directional,
                ..LightDesc::point([1.0, 0.97, 0.92], 1.2, 0.0)
            }),
        },
        Object {
            name: "Floor".into(),
            xform: Xform::at(0.0, -0.1, 0.0).scale(width + 8.0, 0.2, width + 8.0),
            body: Body::Mesh {
                mesh: unity::MeshRef::Builtin(unity::CUBE),
                materials: vec![floor],
            },
        },
    ];
    for n in 0..count {
        let k = n % models;
        let (i, j) = (n % side, n / side);
        objects.push(Object {
            name: format!("Torus{k} ({})", n / models),
            xform: Xform::at(centre(i), 0.0, centre(j)).euler(0.0, (n * 37 % 360) as f32, 0.0),
            body: Body::ModelPrefab {
                guid: guids[k].clone(),
            },
        });
    }
    let scene = SceneDesc {
        ambient: Ambient::Flat([0.1, 0.1, 0.12]),
        fog: None,
        skybox: None,
        reflection: 1.0,
        objects,
    };
    p.add_asset(
        SCENE_PATH,
        unity::write_scene("fbxlarge/FbxLarge", &scene),
        meta::scene,
    );
    p.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_holds_its_triangles_half_of_them_as_quads() {
        let bytes = model_file(3, false);
        let scene = ufbx::load_memory(&bytes, ufbx::LoadOpts::default())
            .unwrap_or_else(|e| panic!("{}", e.description));
        let tris: usize = scene.meshes.iter().map(|m| m.num_triangles).sum();
        assert_eq!(tris, TRIANGLES_PER_MODEL);
        assert_eq!(scene.meshes.len(), PARTS);
        // Half the parts are quads, half triangles.
        let quads = scene
            .meshes
            .iter()
            .filter(|m| m.max_face_triangles == 2)
            .count();
        assert_eq!(quads, PARTS / 2);
        assert_ne!(model_file(4, false), bytes);
    }

    #[test]
    fn a_compressed_model_reads_back_the_same_and_smaller() {
        let opts = || ufbx::LoadOpts {
            strict: true,
            ..Default::default()
        };
        let (raw, zipped) = (model_file(5, false), model_file(5, true));
        assert!(zipped.len() < raw.len());
        let a = ufbx::load_memory(&raw, opts()).unwrap_or_else(|e| panic!("{}", e.description));
        let b = ufbx::load_memory(&zipped, opts()).unwrap_or_else(|e| panic!("{}", e.description));
        assert_eq!(a.meshes.len(), b.meshes.len());
        for (x, y) in a.meshes.iter().zip(b.meshes.iter()) {
            assert_eq!(x.num_triangles, y.num_triangles);
            let ix: Vec<u32> = x.vertex_indices.iter().copied().collect();
            let iy: Vec<u32> = y.vertex_indices.iter().copied().collect();
            assert_eq!(ix, iy);
            let px: Vec<[f64; 3]> = x.vertices.iter().map(|v| [v.x, v.y, v.z]).collect();
            let py: Vec<[f64; 3]> = y.vertices.iter().map(|v| [v.x, v.y, v.z]).collect();
            assert_eq!(px, py);
        }
    }

    #[test]
    fn instances_say_how_often_each_model_is_placed() {
        for (models, instances) in [(2, 1), (3, 4)] {
            let p = project(models, instances, false);
            let scene = String::from_utf8(p.files[SCENE_PATH].clone()).unwrap();
            assert_eq!(scene.matches("--- !u!1001 &").count(), models * instances);
        }
    }

    #[test]
    fn scene_places_each_model_twice_as_a_prefab_with_a_camera_and_a_sun() {
        let p = project(3, INSTANCES, false);
        let scene = String::from_utf8(p.files[SCENE_PATH].clone()).unwrap();
        assert_eq!(scene.matches("--- !u!1001 &").count(), 3 * INSTANCES);
        assert_eq!(scene.matches("--- !u!20 &").count(), 1);
        assert_eq!(scene.matches("--- !u!108 &").count(), 1);
        let roots = scene.split("SceneRoots:").nth(1).unwrap();
        assert_eq!(roots.matches("  - {fileID: ").count(), 3 + 3 * INSTANCES);
        for k in 0..3 {
            let path = format!("Assets/Models/Torus{k}.fbx");
            let meta = String::from_utf8(p.files[&format!("{path}.meta")].clone()).unwrap();
            for key in [
                "    useFileScale: 1\n",
                "    fileIdsGeneration: 2\n",
                "  internalIDToNameTable: []\n",
            ] {
                assert!(meta.contains(key), "{path}.meta lacks {key:?}");
            }
            let guid = meta.lines().find_map(|l| l.strip_prefix("guid: ")).unwrap();
            let source = format!("m_SourcePrefab: {{fileID: 100100000, guid: {guid}, type: 3}}");
            assert_eq!(scene.matches(&source).count(), INSTANCES);
            assert!(p.files[&path].starts_with(b"Kaydara FBX Binary  \0"));
        }
    }
}
