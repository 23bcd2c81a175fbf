//! The `terrain` project: a Unity Terrain of two hills, grass below and rock on the
//! higher slopes. Unity keeps a TerrainData in its binary serialized format even in a
//! Force Text project, so this writes one: a format 22 file (Unity 2022.3) holding the
//! TerrainData and its splat map, each with the type tree Unity embeds in editor files.

use crate::effects::Builder;
use crate::material::MatDesc;
use crate::meta::{self, TextureImport};
use crate::project::Project;
use crate::unity::{self, Ambient, Body, CameraDesc, LightDesc, LightType, Object, Xform};
use glam::Vec3;

/// Heightmap samples a side (64 cells), terrain size in metres and its full height.
pub const RESOLUTION: usize = 65;
pub const SIZE: f32 = 64.0;
pub const HEIGHT: f32 = 16.0;
/// Splat map texels a side.
pub const SPLAT: usize = 32;
/// Above this share of the full height the ground is rock.
pub const ROCK_ABOVE: f32 = 0.4;
/// Where the terrain's corner stands.
pub const POSITION: Vec3 = Vec3::new(-32.0, 0.0, -20.0);
/// How many trees stand on the terrain, scattered over the grass below the rock line.
pub const TREES: usize = 24;
/// The path ID of the main object of a TerrainData asset and of a TerrainLayer asset.
const TERRAIN_DATA_ID: i64 = 15600000;
const TERRAIN_LAYER_ID: i64 = 8574412962073106934;

/// The ground's height, 0 to 1 of the full height, at terrain coordinates `u`, `v` (0–1):
/// a high hill at the back right and a low one at the front left.
pub fn height(u: f32, v: f32) -> f32 {
    let hill = |cu: f32, cv: f32, r: f32, h: f32| {
        let d2 = (u - cu).powi(2) + (v - cv).powi(2);
        h * (-d2 / (2.0 * r * r)).exp()
    };
    0.05 + hill(0.65, 0.6, 0.15, 0.85) + hill(0.3, 0.35, 0.12, 0.3)
}

/// One painted tree: where it stands (terrain coordinates 0–1, y the ground's share of
/// the full height), its width and height scales and its turn in radians.
pub struct Tree {
    pub position: Vec3,
    pub width: f32,
    pub height: f32,
    pub rotation: f32,
}

/// The trees: a jittered grid over the front half of the terrain, every place below the
/// rock line kept until there are `TREES`.
pub fn trees() -> Vec<Tree> {
    // A fixed hash of the index: the same forest every time.
    let hash = |k: u32, salt: u32| {
        let h = (k ^ salt.wrapping_mul(0x9e37_79b9)).wrapping_mul(0x85eb_ca6b);
        ((h ^ h >> 13).wrapping_mul(0xc2b2_ae35) >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut out = Vec::new();
    for k in 0..200u32 {
        let (i, j) = (k % 10, k / 10);
        let u = 0.05 + (i as f32 + hash(k, 1)) * 0.09;
        let v = 0.08 + (j as f32 + hash(k, 2)) * 0.05;
        let ground = height(u, v);
        if ground > ROCK_ABOVE - 0.1 || u > 0.95 {
            continue;
        }
        out.push(Tree {
            position: Vec3::new(u, ground, v),
            width: 0.8 + 0.4 * hash(k, 3),
            height: 0.8 + 0.5 * hash(k, 4),
            rotation: std::f32::consts::TAU * hash(k, 5),
        });
        if out.len() == TREES {
            break;
        }
    }
    out
}

/// A byte buffer in little-endian order with Unity's 4-byte alignment.
#[derive(Default)]
struct Bytes(Vec<u8>);

impl Bytes {
    fn i32(&mut self, v: i32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn i64(&mut self, v: i64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn cstr(&mut self, s: &str) {
        self.0.extend_from_slice(s.as_bytes());
        self.0.push(0);
    }
    fn align(&mut self) {
        while !self.0.len().is_multiple_of(4) {
            self.0.push(0);
        }
    }
    /// A `string` field: its length, its bytes, then alignment.
    fn string(&mut self, s: &str) {
        self.i32(s.len() as i32);
        self.0.extend_from_slice(s.as_bytes());
        self.align();
    }
}

/// `metaFlag` bit: align after this node.
const ALIGN: u32 = 0x4000;

/// A type tree node: (level, type, name, byte size, flags (1: an array), metaFlag).
type Node = (u8, &'static str, &'static str, i32, u8, u32);

fn string_nodes(level: u8, name: &'static str) -> [Node; 4] {
    [
        (level, "string", name, -1, 0, 0x8000),
        (level + 1, "Array", "Array", -1, 1, ALIGN),
        (level + 2, "int", "size", 4, 0, 0),
        (level + 2, "char", "data", 1, 0, 0),
    ]
}

fn pptr_vector(name: &'static str, target: &'static str) -> [Node; 6] {
    [
        (2, "vector", name, -1, 0, 0),
        (3, "Array", "Array", -1, 1, 0),
        (4, "int", "size", 4, 0, 0),
        (4, target, "data", 12, 0, 0),
        (5, "int", "m_FileID", 4, 0, 0),
        (5, "SInt64", "m_PathID", 8, 0, 0),
    ]
}

fn terrain_data_tree() -> Vec<Node> {
    let mut n = vec![(0, "TerrainData", "Base", -1, 0, 0)];
    n.extend(string_nodes(1, "m_Name"));
    n.push((1, "SplatDatabase", "m_SplatDatabase", -1, 0, 0));
    n.extend(pptr_vector("m_TerrainLayers", "PPtr<TerrainLayer>"));
    n.extend(pptr_vector("m_AlphaTextures", "PPtr<Texture2D>"));
    n.extend([
        (1, "DetailDatabase", "m_DetailDatabase", -1, 0, 0),
        (2, "vector", "m_TreePrototypes", -1, 0, 0),
        (3, "Array", "Array", -1, 1, 0),
        (4, "int", "size", 4, 0, 0),
        (4, "TreePrototype", "data", -1, 0, 0),
        (5, "PPtr<GameObject>", "prefab", 12, 0, 0),
        (6, "int", "m_FileID", 4, 0, 0),
        (6, "SInt64", "m_PathID", 8, 0, 0),
        (5, "float", "bendFactor", 4, 0, 0),
        (5, "int", "navMeshLod", 4, 0, 0),
        (2, "vector", "m_TreeInstances", -1, 0, 0),
        (3, "Array", "Array", -1, 1, 0),
        (4, "int", "size", 4, 0, 0),
        (4, "TreeInstance", "data", 40, 0, 0),
        (5, "Vector3f", "position", 12, 0, 0),
        (6, "float", "x", 4, 0, 0),
        (6, "float", "y", 4, 0, 0),
        (6, "float", "z", 4, 0, 0),
        (5, "float", "widthScale", 4, 0, 0),
        (5, "float", "heightScale", 4, 0, 0),
        (5, "float", "rotation", 4, 0, 0),
        (5, "ColorRGBA", "color", 4, 0, 0),
        (6, "unsigned int", "rgba", 4, 0, 0),
        (5, "ColorRGBA", "lightmapColor", 4, 0, 0),
        (6, "unsigned int", "rgba", 4, 0, 0),
        (5, "int", "index", 4, 0, 0),
        (1, "Heightmap", "m_Heightmap", -1, 0, 0),
        (2, "vector", "m_Heights", -1, 0, 0),
        (3, "Array", "Array", -1, 1, ALIGN),
        (4, "int", "size", 4, 0, 0),
        (4, "SInt16", "data", 2, 0, 0),
        (2, "int", "m_Resolution", 4, 0, 0),
        (2, "Vector3f", "m_Scale", 12, 0, 0),
        (3, "float", "x", 4, 0, 0),
        (3, "float", "y", 4, 0, 0),
        (3, "float", "z", 4, 0, 0),
    ]);
    n
}

fn texture_tree() -> Vec<Node> {
    let mut n = vec![(0, "Texture2D", "Base", -1, 0, 0)];
    n.extend(string_nodes(1, "m_Name"));
    n.extend([
        (1, "int", "m_Width", 4, 0, 0),
        (1, "int", "m_Height", 4, 0, 0),
        (1, "int", "m_TextureFormat", 4, 0, 0),
        (1, "TypelessData", "image data", -1, 1, ALIGN),
        (2, "int", "size", 4, 0, 0),
        (2, "UInt8", "data", 1, 0, 0),
    ]);
    n
}

/// A type tree in the blob layout of format 19 and later (strings in the file's own
/// buffer).
fn write_tree(w: &mut Bytes, nodes: &[Node]) {
    let mut strings = Bytes::default();
    let mut offset = |s: &str| {
        let at = strings.0.len() as u32;
        strings.cstr(s);
        at
    };
    let offsets: Vec<(u32, u32)> = nodes.iter().map(|n| (offset(n.1), offset(n.2))).collect();
    w.i32(nodes.len() as i32);
    w.i32(strings.0.len() as i32);
    for (i, (&(level, _, _, size, flags, meta), (t, name))) in nodes.iter().zip(offsets).enumerate()
    {
        w.0.extend_from_slice(&1u16.to_le_bytes());
        w.0.extend_from_slice(&[level, flags]);
        w.0.extend_from_slice(&t.to_le_bytes());
        w.0.extend_from_slice(&name.to_le_bytes());
        w.i32(size);
        w.i32(i as i32);
        w.0.extend_from_slice(&meta.to_le_bytes());
        w.i64(0);
    }
    w.0.extend_from_slice(&strings.0);
}

/// A GUID as its 16 raw bytes: Unity writes each byte's low nibble first in text.
fn guid_bytes(guid: &str) -> [u8; 16] {
    let nibble = |c: u8| (c as char).to_digit(16).expect("a hex GUID") as u8;
    let g = guid.as_bytes();
    std::array::from_fn(|i| nibble(g[2 * i]) | nibble(g[2 * i + 1]) << 4)
}

/// The TerrainData asset: `RESOLUTION`² heights from [`height`], the layers with these
/// GUIDs, one RGBA32 splat map weighing the first layer (R) below `ROCK_ABOVE` and the
/// second (G) above it, and [`trees`] of the prefab with GUID `tree` (its root
/// GameObject `tree_root`).
pub fn terrain_data(layers: &[String], tree: &str, tree_root: i64) -> Vec<u8> {
    let cells = (RESOLUTION - 1) as f32;
    let mut data = Bytes::default();
    data.string("Hills");
    data.i32(layers.len() as i32);
    for i in 0..layers.len() {
        data.i32(i as i32 + 1);
        data.i64(TERRAIN_LAYER_ID);
    }
    data.i32(1);
    data.i32(0);
    data.i64(2);
    // The tree prefab is the external after the layers.
    data.i32(1);
    data.i32(layers.len() as i32 + 1);
    data.i64(tree_root);
    data.f32(0.0);
    data.i32(i32::MAX);
    let trees = trees();
    data.i32(trees.len() as i32);
    for t in &trees {
        let p = t.position;
        for v in [p.x, p.y, p.z, t.width, t.height, t.rotation] {
            data.f32(v);
        }
        data.i32(-1);
        data.i32(-1);
        data.i32(0);
    }
    data.i32((RESOLUTION * RESOLUTION) as i32);
    for z in 0..RESOLUTION {
        for x in 0..RESOLUTION {
            let h = height(x as f32 / cells, z as f32 / cells);
            data.0
                .extend_from_slice(&((h * 32766.0).round() as i16).to_le_bytes());
        }
    }
    data.align();
    data.i32(RESOLUTION as i32);
    for v in [SIZE / cells, HEIGHT, SIZE / cells] {
        data.f32(v);
    }
    let mut splat = Bytes::default();
    splat.string("SplatAlpha 0");
    for v in [SPLAT as i32, SPLAT as i32, 4, (SPLAT * SPLAT * 4) as i32] {
        splat.i32(v);
    }
    for z in 0..SPLAT {
        for x in 0..SPLAT {
            let centre = |k: usize| (k as f32 + 0.5) / SPLAT as f32;
            let rock = height(centre(x), centre(z)) > ROCK_ABOVE;
            splat.0.extend_from_slice(if rock {
                &[0, 255, 0, 0]
            } else {
                &[255, 0, 0, 0]
            });
        }
    }
    serialized_file(
        &[(156, terrain_data_tree()), (28, texture_tree())],
        &[(TERRAIN_DATA_ID, 0, data.0), (2, 1, splat.0)],
        &[layers, &[tree.to_string()]].concat(),
    )
}

/// A format 22 serialized file (little-endian data) of `types` (class, tree), `objects`
/// (path ID, type index, data) and externals with `guids`.
fn serialized_file(
    types: &[(i32, Vec<Node>)],
    objects: &[(i64, i32, Vec<u8>)],
    guids: &[String],
) -> Vec<u8> {
    const HEADER: usize = 48;
    let mut w = Bytes(vec![0; HEADER]);
    w.cstr("2022.3.0f1");
    w.i32(19);
    w.0.push(1);
    w.i32(types.len() as i32);
    for (class, tree) in types {
        w.i32(*class);
        w.0.push(0);
        w.0.extend_from_slice(&(-1i16).to_le_bytes());
        w.0.extend_from_slice(&[0; 16]);
        write_tree(&mut w, tree);
        w.i32(0);
    }
    // Object data at 8-byte boundaries of the data section.
    let mut starts = Vec::new();
    let mut end = 0;
    for (_, _, bytes) in objects {
        starts.push(end);
        end = (end + bytes.len()).next_multiple_of(8);
    }
    w.i32(objects.len() as i32);
    for ((path_id, type_index, bytes), start) in objects.iter().zip(&starts) {
        w.align();
        w.i64(*path_id);
        w.i64(*start as i64);
        w.i32(bytes.len() as i32);
        w.i32(*type_index);
    }
    w.i32(0);
    w.i32(guids.len() as i32);
    for guid in guids {
        w.cstr("");
        w.0.extend_from_slice(&guid_bytes(guid));
        w.i32(2);
        w.cstr("");
    }
    let metadata = w.0.len() - HEADER;
    let data_offset = w.0.len().next_multiple_of(16);
    for ((_, _, bytes), start) in objects.iter().zip(&starts) {
        w.0.resize(data_offset + start, 0);
        w.0.extend_from_slice(bytes);
    }
    // The header is big-endian.
    let mut h = Vec::with_capacity(HEADER);
    h.extend_from_slice(&[0; 8]);
    h.extend_from_slice(&22u32.to_be_bytes());
    h.extend_from_slice(&[0; 8]);
    h.extend_from_slice(&(metadata as u32).to_be_bytes());
    h.extend_from_slice(&(w.0.len() as i64).to_be_bytes());
    h.extend_from_slice(&(data_offset as i64).to_be_bytes());
    h.extend_from_slice(&[0; 8]);
    w.0[..HEADER].copy_from_slice(&h);
    w.0
}

/// A TerrainLayer asset showing texture `texture`, one tile every `tile` metres.
fn terrain_layer(name: &str, texture: &str, tile: f32) -> String {
    format!(
        "%YAML 1.1
%TAG !u! tag:unity3d.com,2011:
--- !u!1953259897 &{TERRAIN_LAYER_ID}
TerrainLayer:
  m_ObjectHideFlags: 0
  m_CorrespondingSourceObject: {{fileID: 0}}
  m_PrefabInstance: {{fileID: 0}}
  m_PrefabAsset: {{fileID: 0}}
  m_Name: {name}
  m_DiffuseTexture: {{fileID: 2800000, guid: {texture}, type: 3}}
  m_NormalMapTexture: {{fileID: 0}}
  m_MaskMapTexture: {{fileID: 0}}
  m_TileSize: {{x: {tile}, y: {tile}}}
  m_TileOffset: {{x: 0, y: 0}}
  m_Specular: {{r: 0, g: 0, b: 0, a: 0}}
  m_Metallic: 0
  m_Smoothness: 0
  m_NormalScale: 1
  m_DiffuseRemapMin: {{x: 0, y: 0, z: 0, w: 0}}
  m_DiffuseRemapMax: {{x: 1, y: 1, z: 1, w: 1}}
  m_MaskMapRemapMin: {{x: 0, y: 0, z: 0, w: 0}}
  m_MaskMapRemapMax: {{x: 1, y: 1, z: 1, w: 1}}
  m_SmoothnessSource: 1
"
    )
}

/// A 4×4 PNG of two shades of `colour` in a checker, so a layer's tiling shows.
fn checker(colour: [u8; 3]) -> Vec<u8> {
    let dark = colour.map(|c| (c as u32 * 4 / 5) as u8);
    let img = image::RgbImage::from_fn(4, 4, |x, y| {
        image::Rgb(if (x / 2 + y / 2) % 2 == 0 {
            colour
        } else {
            dark
        })
    });
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("a PNG in memory");
    out.into_inner()
}

/// The project: the terrain under a low sun, seen from the front.
pub fn project() -> Project {
    let mut b = Builder::new(
        "terrain",
        &[
            MatDesc::matte("Bark", [0.36, 0.24, 0.14]),
            MatDesc::matte("Leaves", [0.16, 0.42, 0.12]),
        ],
    );
    // A round tree 4.5 m tall: a trunk (Unity's cylinder is 2 m tall and 1 m across) sunk
    // 0.2 m into the ground, under an ellipsoid crown.
    let (bark, leaves) = (
        b.guid("Assets/Materials/Bark.mat"),
        b.guid("Assets/Materials/Leaves.mat"),
    );
    let (prefab, tree_root) = unity::write_prefab(
        "terrain/Tree",
        "Tree",
        &Xform::at(0.0, 0.0, 0.0),
        &[
            (
                "Trunk",
                unity::CYLINDER,
                &bark,
                Xform::at(0.0, 0.8, 0.0).scale(0.3, 1.0, 0.3),
            ),
            (
                "Crown",
                unity::SPHERE,
                &leaves,
                Xform::at(0.0, 3.0, 0.0).scale(2.2, 3.0, 2.2),
            ),
        ],
    );
    let tree = b.asset(
        "Assets/Terrain/Tree.prefab",
        prefab.into_bytes(),
        meta::prefab,
    );
    let import = TextureImport {
        filter: 1,
        mipmaps: true,
        srgb: true,
        wrap: 0,
        alpha_is_transparency: false,
        normal_map: false,
    };
    let mut layers = Vec::new();
    for (name, colour) in [("Grass", [86, 140, 52]), ("Rock", [128, 118, 108])] {
        let texture = b.texture(
            &format!("Assets/Terrain/{name}.png"),
            checker(colour),
            &import,
        );
        let path = format!("Assets/Terrain/{name}.terrainlayer");
        layers.push(b.asset(
            &path,
            terrain_layer(name, &texture, 4.0).into_bytes(),
            meta::terrain_layer,
        ));
    }
    let data = b.asset(
        "Assets/Terrain/Hills.asset",
        terrain_data(&layers, &tree, tree_root),
        meta::terrain_data,
    );
    b.object(Object {
        name: "Terrain".into(),
        xform: Xform::at(POSITION.x, POSITION.y, POSITION.z),
        body: Body::Terrain { data },
    })
    .camera(
        Xform::at(0.0, 16.0, -36.0).euler(18.0, 0.0, 0.0),
        CameraDesc {
            skybox: true,
            ..CameraDesc::default()
        },
    )
    .light(
        "Directional Light",
        Xform::at(0.0, 20.0, 0.0).euler(35.0, -50.0, 0.0),
        LightDesc {
            kind: LightType::Directional,
            shadows: 1,
            ..LightDesc::point([1.0, 0.96, 0.88], 1.0, 10.0)
        },
    );
    b.finish("Terrain", Ambient::Skybox(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hills_rise_above_the_rock_line_and_the_edges_do_not() {
        assert!(height(0.65, 0.6) > 0.85, "the high hill's top");
        assert!(
            (0.3..ROCK_ABOVE).contains(&height(0.3, 0.35)),
            "a low grassy hill"
        );
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.05)] {
            assert!(height(u, v) < 0.1, "({u}, {v})");
        }
        assert_eq!(guid_bytes("0123456789abcdef0123456789abcdef")[0], 0x10);
    }
}
