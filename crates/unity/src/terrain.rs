//! Terrain (class 218): the heightmap of its TerrainData as a grid of triangles, each
//! cell drawn with the texture of the layer its splat maps weigh most at the cell's
//! centre, tiled as that layer tiles it.
//!
//! Unity writes TerrainData assets in its binary format whatever the project's
//! serialization mode, so they are read through [`crate::serialized`]. A height is a
//! 16-bit sample where 32766 is the terrain's full height (Unity's terrain tools scale
//! heights by 32766 / 65535 into a 16-bit texture). A terrain ignores its Transform's
//! rotation and scale: it lies along the world axes from its position. Painted holes are
//! cut out cell by cell. Its painted trees are read here and planted with the scene's
//! objects ([`crate::trees`]). The smooth blend between layers and detail grass are not
//! converted; a warning names a terrain with more than one layer and how much of it each
//! covers.

use crate::emit::{EmitError, Emitter};
use crate::reference::Ref;
use crate::serialized::{SerializedFile, Value};
use crate::texture::TextureSlot;
use formats::texture::Tiling;
use formats::{CastShadows, Material, Object};
use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

/// The class of a TerrainData object.
const TERRAIN_DATA: i32 = 156;
/// The height sample that stands for the terrain's full height.
const FULL_HEIGHT: f32 = 32766.0;
/// The most grid cells a side is drawn with: a 4097² heightmap would be 33.5 million
/// triangles; beyond this many, every k-th sample is taken (Unity itself draws distant
/// parts of a terrain at coarser levels of detail).
const MAX_CELLS: usize = 1024;

/// A terrain's geometry, read from its TerrainData.
pub struct Heightfield {
    /// Samples per side.
    pub resolution: usize,
    /// Row-major, rows along z: `heights[z * resolution + x]`, 0 to 1 of the full height.
    pub heights: Vec<f32>,
    /// Terrain size in metres (x, full height, z).
    pub size: Vec3,
}

/// One terrain layer: its albedo texture by GUID and how it tiles.
#[derive(Clone)]
pub struct Layer {
    pub name: String,
    pub texture: Option<String>,
    pub tile_size: Vec2,
    pub tile_offset: Vec2,
    pub smoothness: f32,
    pub metallic: f32,
}

/// A TerrainData as read: its heightfield, its layers' GUIDs (of TerrainLayer assets, or
/// with older files the textures of inline splat prototypes), and its splat maps (None
/// when they cannot be read).
pub struct TerrainData {
    pub field: Heightfield,
    pub layers: LayerRefs,
    pub splat: Option<Splat>,
    /// Painted holes (`m_Holes`, called `m_SurfaceMask` in the first versions to paint
    /// them, Unity 2019.3): one byte per cell, rows along z, 0 where the surface is cut
    /// away; empty until a hole is painted.
    pub holes: Vec<u8>,
    pub trees: Trees,
}

/// The trees painted on a terrain.
#[derive(Debug, Default, PartialEq)]
pub struct Trees {
    /// Per prototype, the GUID of its prefab or model (None: no prefab set).
    pub prototypes: Vec<Option<String>>,
    pub instances: Vec<TreeInstance>,
}

/// One painted tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeInstance {
    /// Where it stands, 0 to 1 across the terrain's size on each axis (y of its full
    /// height), from the terrain's corner.
    pub position: Vec3,
    /// Its prototype's scale across (x and z) and up.
    pub width: f32,
    pub height: f32,
    /// Its turn about the vertical axis, radians.
    pub rotation: f32,
    pub prototype: usize,
}

/// The splat maps: RGBA textures over the terrain whose channels R, G, B, A weigh layers
/// 4k to 4k + 3, row 0 at the terrain's z = 0 edge.
pub struct Splat {
    pub maps: Vec<SplatMap>,
}

pub struct SplatMap {
    pub width: usize,
    pub height: usize,
    /// R, G, B, A per texel, rows from the bottom.
    pub texels: Vec<[u8; 4]>,
}

impl Splat {
    /// Layer `layer`'s weight (0–255) at terrain coordinates `u`, `v` in 0..1, from the
    /// nearest texel.
    pub fn weight(&self, layer: usize, u: f32, v: f32) -> u8 {
        let Some(map) = self.maps.get(layer / 4) else {
            return 0;
        };
        let at = |t: f32, n: usize| ((t * n as f32) as usize).min(n - 1);
        map.texels[at(v, map.height) * map.width + at(u, map.width)][layer % 4]
    }

    /// The share of the terrain each layer's weight covers.
    pub fn coverage(&self) -> Vec<f64> {
        self.maps
            .iter()
            .flat_map(|m| {
                let mut sums = [0u64; 4];
                for t in &m.texels {
                    for (s, &w) in sums.iter_mut().zip(t) {
                        *s += w as u64;
                    }
                }
                sums.map(|s| s as f64 / (255.0 * m.texels.len() as f64))
            })
            .collect()
    }
}

/// Read TerrainData `id` of a binary asset.
pub fn read(file: &SerializedFile, id: i64) -> Result<TerrainData, String> {
    let object = file
        .objects
        .iter()
        .find(|o| o.path_id == id && o.class_id == TERRAIN_DATA)
        .or_else(|| file.objects.iter().find(|o| o.class_id == TERRAIN_DATA))
        .ok_or("holds no TerrainData")?;
    let data = file.read(object.path_id).map_err(|e| e.to_string())?;
    let hm = data
        .get("m_Heightmap")
        .ok_or("TerrainData has no m_Heightmap")?;
    let resolution = hm
        .get("m_Resolution")
        .or_else(|| hm.get("m_Width"))
        .and_then(Value::as_i64)
        .ok_or("m_Heightmap has no resolution")?;
    let Some(Value::Numbers(samples)) = hm.get("m_Heights") else {
        return Err("m_Heightmap has no m_Heights".into());
    };
    let resolution = usize::try_from(resolution).unwrap_or(0);
    if resolution < 2 || samples.len() != resolution * resolution {
        return Err(format!(
            "m_Heights holds {} samples for a resolution of {resolution}",
            samples.len()
        ));
    }
    let scale = hm.get("m_Scale").ok_or("m_Heightmap has no m_Scale")?;
    let axis = |k: &str| scale.get(k).and_then(Value::as_f64).map(|v| v as f32);
    let (Some(sx), Some(sy), Some(sz)) = (axis("x"), axis("y"), axis("z")) else {
        return Err("m_Scale is not a vector".into());
    };
    let cells = (resolution - 1) as f32;
    let size = Vec3::new(sx * cells, sy, sz * cells);
    if !size.is_finite() {
        return Err(format!("its size {size} is not finite"));
    }
    let heights = samples
        .iter()
        .map(|&h| (h as f32 / FULL_HEIGHT).clamp(0.0, 1.0))
        .collect();
    let field = Heightfield {
        resolution,
        heights,
        size,
    };
    let holes = match hm.get("m_Holes").or(hm.get("m_SurfaceMask")) {
        Some(Value::Bytes(b)) => b.clone(),
        _ => Vec::new(),
    };
    Ok(TerrainData {
        holes,
        field,
        layers: layer_refs(file, &data),
        splat: splat(file, &data),
        trees: trees(file, &data),
    })
}

/// TerrainData `id` of the binary asset at `path` (`rel` in messages).
pub(crate) fn load(path: &std::path::Path, rel: &str, id: i64) -> Result<TerrainData, String> {
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    if !SerializedFile::is_serialized_file(&bytes) {
        return Err("is not a binary Unity asset".into());
    }
    let file = SerializedFile::parse(bytes, rel).map_err(|e| e.to_string())?;
    read(&file, id)
}

/// The tree prototypes and instances of a TerrainData's detail database; an instance
/// with a value that is not finite is left out.
fn trees(file: &SerializedFile, data: &Value) -> Trees {
    let db = data.get("m_DetailDatabase");
    let seq = |key: &str| match db.and_then(|d| d.get(key)) {
        Some(Value::Seq(items)) => items.as_slice(),
        _ => &[],
    };
    let prototypes = seq("m_TreePrototypes")
        .iter()
        .map(|p| p.get("prefab").and_then(|r| guid_of(file, r)))
        .collect();
    let instances = seq("m_TreeInstances")
        .iter()
        .filter_map(|t| {
            let f = |v: Option<&Value>| v.and_then(Value::as_f64).map(|x| x as f32);
            let p = |k: &str| f(t.path(&["position", k]));
            let instance = TreeInstance {
                position: Vec3::new(p("x")?, p("y")?, p("z")?),
                width: f(t.get("widthScale"))?,
                height: f(t.get("heightScale"))?,
                rotation: f(t.get("rotation")).unwrap_or(0.0),
                prototype: t
                    .get("index")
                    .or(t.get("prototypeIndex"))
                    .and_then(Value::as_i64)
                    .and_then(|i| usize::try_from(i).ok())?,
            };
            let finite = instance.position.is_finite()
                && [instance.width, instance.height, instance.rotation]
                    .iter()
                    .all(|v| v.is_finite());
            finite.then_some(instance)
        })
        .collect();
    Trees {
        prototypes,
        instances,
    }
}

/// The splat maps of a TerrainData, if every one is in the file as an RGBA32 or ARGB32
/// texture (Unity writes them so).
fn splat(file: &SerializedFile, data: &Value) -> Option<Splat> {
    let Some(Value::Seq(refs)) = data.path(&["m_SplatDatabase", "m_AlphaTextures"]) else {
        return None;
    };
    let mut maps = Vec::new();
    for r in refs {
        let texture = file.read(r.get("m_PathID")?.as_i64()?).ok()?;
        let side = |k: &str| usize::try_from(texture.get(k)?.as_i64()?).ok();
        let (width, height) = (side("m_Width")?, side("m_Height")?);
        // Where R, G, B and A are in a texel's bytes.
        let order = match texture.get("m_TextureFormat")?.as_i64()? {
            4 => [0, 1, 2, 3],
            5 => [1, 2, 3, 0],
            _ => return None,
        };
        let Some(Value::Bytes(bytes)) = texture.get("image data") else {
            return None;
        };
        // The first mip level, the full-size map.
        let level = bytes.get(..width.checked_mul(height)?.checked_mul(4)?)?;
        if level.is_empty() {
            return None;
        }
        let texels = level
            .chunks_exact(4)
            .map(|t| order.map(|at| t[at]))
            .collect();
        maps.push(SplatMap {
            width,
            height,
            texels,
        });
    }
    Some(Splat { maps })
}

/// Where a TerrainData's layers are: TerrainLayer assets (Unity 2018.3 and later) or
/// splat prototypes written inline (earlier).
pub enum LayerRefs {
    Assets(Vec<Option<String>>),
    Inline(Vec<Layer>),
}

/// The GUID a PPtr of `file` names (None for a local or empty reference).
fn guid_of(file: &SerializedFile, pptr: &Value) -> Option<String> {
    let index = pptr.get("m_FileID")?.as_i64()?;
    let external = file
        .externals
        .get(usize::try_from(index).ok()?.checked_sub(1)?)?;
    Some(external.guid.clone())
}

fn layer_refs(file: &SerializedFile, data: &Value) -> LayerRefs {
    let splat = data.get("m_SplatDatabase");
    let seq = |key: &str| match splat.and_then(|s| s.get(key)) {
        Some(Value::Seq(items)) => Some(items.as_slice()),
        _ => None,
    };
    if let Some(layers) = seq("m_TerrainLayers") {
        return LayerRefs::Assets(layers.iter().map(|p| guid_of(file, p)).collect());
    }
    let prototypes = seq("m_Splats").unwrap_or_default();
    let vec2 = |v: Option<&Value>, default: f32| {
        let axis = |k| v.and_then(|v| v.get(k)).and_then(Value::as_f64);
        Vec2::new(
            axis("x").unwrap_or(default as f64) as f32,
            axis("y").unwrap_or(default as f64) as f32,
        )
    };
    LayerRefs::Inline(
        prototypes
            .iter()
            .enumerate()
            .map(|(i, p)| Layer {
                name: format!("splat {i}"),
                texture: p.get("texture").and_then(|t| guid_of(file, t)),
                tile_size: vec2(p.get("tileSize"), 15.0),
                tile_offset: vec2(p.get("tileOffset"), 0.0),
                smoothness: p.get("smoothness").and_then(Value::as_f64).unwrap_or(0.0) as f32,
                metallic: p.get("metallic").and_then(Value::as_f64).unwrap_or(0.0) as f32,
            })
            .collect(),
    )
}

/// A TerrainLayer asset (`.terrainlayer`, text YAML).
pub fn layer_asset(text: &str, name: &str) -> Option<Layer> {
    let body = crate::docs::first(text, crate::docs::TERRAIN_LAYER)?;
    let v2 = |k: &str, default: Vec2| {
        body.get(k)
            .and_then(|n| Some(Vec2::new(n.f32_at("x")?, n.f32_at("y")?)))
            .unwrap_or(default)
    };
    let texture = body.get("m_DiffuseTexture").and_then(|n| {
        let r = Ref::read(Some(n), 0);
        r.guid.filter(|_| r.file_id != 0)
    });
    Some(Layer {
        name: body.str_at("m_Name").unwrap_or(name).to_string(),
        texture,
        tile_size: v2("m_TileSize", Vec2::splat(15.0)),
        tile_offset: v2("m_TileOffset", Vec2::ZERO),
        smoothness: body.f32_at("m_Smoothness").unwrap_or(0.0),
        metallic: body.f32_at("m_Metallic").unwrap_or(0.0),
    })
}

impl Heightfield {
    /// The grid as a mesh in the terrain's own space (Unity axes, origin at its corner),
    /// every `step`-th sample a vertex, UVs 0 to 1 across it; each cell's two triangles in
    /// sub-mesh `part(u, v)` of `parts`, (u, v) the cell's centre, or none where `part`
    /// says None (a hole).
    pub fn mesh(
        &self,
        parts: usize,
        part: impl Fn(f32, f32) -> Option<usize>,
    ) -> crate::mesh::Mesh {
        let res = self.resolution;
        let step = (res - 1).div_ceil(MAX_CELLS);
        let n = (res - 1) / step + 1;
        // The last row and column always reach the far edge.
        let sample = |k: usize| (k * step).min(res - 1);
        let h = |x: usize, z: usize| self.heights[sample(z) * res + sample(x)] * self.size.y;
        let along = |k: usize, extent: f32| sample(k) as f32 / (res - 1) as f32 * extent;
        let mut positions = Vec::with_capacity(n * n);
        let mut normals = Vec::with_capacity(n * n);
        let mut uvs = Vec::with_capacity(n * n);
        for z in 0..n {
            for x in 0..n {
                let (px, pz) = (along(x, self.size.x), along(z, self.size.z));
                positions.push(Vec3::new(px, h(x, z), pz));
                uvs.push(Vec2::new(
                    sample(x) as f32 / (res - 1) as f32,
                    sample(z) as f32 / (res - 1) as f32,
                ));
                // Central differences (one-sided at the edges) across the drawn grid.
                let (x0, x1) = (x.saturating_sub(1), (x + 1).min(n - 1));
                let (z0, z1) = (z.saturating_sub(1), (z + 1).min(n - 1));
                let dx = (h(x1, z) - h(x0, z)) / (along(x1, self.size.x) - along(x0, self.size.x));
                let dz = (h(x, z1) - h(x, z0)) / (along(z1, self.size.z) - along(z0, self.size.z));
                let normal = Vec3::new(-dx, 1.0, -dz).normalize_or(Vec3::Y);
                normals.push(normal);
            }
        }
        let v = |x: usize, z: usize| (z * n + x) as u32;
        let mut submeshes = vec![Vec::new(); parts.max(1)];
        for z in 0..n - 1 {
            for x in 0..n - 1 {
                let centre = |a: Vec2, b: Vec2| (a + b) / 2.0;
                let c = centre(uvs[v(x, z) as usize], uvs[v(x + 1, z + 1) as usize]);
                let Some(p) = part(c.x, c.y) else { continue };
                let tris = &mut submeshes[p.min(parts.max(1) - 1)];
                // Clockwise seen from above: Unity's front faces, facing +y.
                tris.push([v(x, z), v(x, z + 1), v(x + 1, z)]);
                tris.push([v(x, z + 1), v(x + 1, z + 1), v(x + 1, z)]);
            }
        }
        crate::mesh::Mesh {
            positions,
            normals,
            submeshes,
            uvs,
        }
    }
}

impl Emitter<'_, '_> {
    /// Draw Terrain component `terrain` on GameObject `go`, or say why not.
    pub(crate) fn terrain(&mut self, go: usize, terrain: usize) -> Result<(), EmitError> {
        let g = self.g;
        let what = self.describe(go);
        let body = &g.objs[terrain].body;
        if body.i64_at("m_DrawHeightmap") == Some(0) {
            return Ok(());
        }
        let r = Ref::read(body.get("m_TerrainData"), g.objs[terrain].file);
        let Some(guid) = r.guid.as_deref().filter(|_| r.file_id != 0) else {
            self.warn(format!("{what}: Terrain has no TerrainData; skipped"));
            return Ok(());
        };
        let Some(path) = g.project.resolve(guid).cloned() else {
            self.warn(format!(
                "{what}: TerrainData GUID {guid} is not in the project; skipped"
            ));
            return Ok(());
        };
        let rel = g.project.rel(&path);
        let parsed = g.project.terrain_data(&path, r.file_id);
        let TerrainData {
            field,
            layers,
            splat,
            holes,
            trees: _, // planted with the scene's objects (`crate::trees`)
        } = match parsed.as_ref() {
            Ok(x) => x,
            Err(why) => {
                self.warn(format!("{what}: TerrainData {rel}: {why}; skipped"));
                return Ok(());
            }
        };
        let world = self.checked_world(go)?;
        // A terrain takes its position alone.
        let world = Mat4::from_translation(world.w_axis.truncate());
        let layers = self.terrain_layers(layers, &what);
        let coverage = splat.as_ref().map(Splat::coverage).unwrap_or_default();
        self.warn_layers(&layers, &coverage, &what);
        let cells = field.resolution - 1;
        let holes: &[u8] = if holes.is_empty() || holes.len() == cells * cells {
            holes
        } else {
            self.warn(format!(
                "{what}: its holes are not cut: m_Holes holds {} bytes for {cells}×{cells} cells",
                holes.len()
            ));
            &[]
        };
        // The cell under a point, as the holes texture is sampled.
        let cell = |t: f32| ((t * cells as f32) as usize).min(cells - 1);
        let hole = |u: f32, v: f32| holes.get(cell(v) * cells + cell(u)) == Some(&0);
        if field.resolution - 1 > MAX_CELLS {
            let step = (field.resolution - 1).div_ceil(MAX_CELLS);
            self.warn(format!(
                "{what}: its {r}×{r} heightmap is drawn from one sample in {step} along \
                 each side ({MAX_CELLS} cells a side at most)",
                r = field.resolution
            ));
        }
        // Each cell takes the drawn layer that weighs most at its centre (the first of
        // equals); without splat maps, every cell the first drawn layer. A cell whose
        // centre is in a hole is not drawn (a sub-sampled cell is one of its centre's).
        let drawn: Vec<usize> = (0..layers.len()).filter(|&i| layers[i].is_some()).collect();
        let mesh = Arc::new(field.mesh(drawn.len().max(1), |u, v| {
            if hole(u, v) {
                return None;
            }
            let weight = |i: usize| splat.as_ref().map_or(0, |s| s.weight(drawn[i], u, v));
            (0..drawn.len())
                .reduce(|best, i| if weight(i) > weight(best) { i } else { best })
                .or(Some(0))
        }));
        // Materials only for the layers that draw a cell: each decodes a texture.
        let mut parts = Vec::new();
        for (i, tris) in mesh.submeshes.iter().enumerate() {
            if tris.is_empty() {
                continue;
            }
            let material = match drawn.get(i).and_then(|&l| layers[l].as_ref()) {
                Some(layer) => self.layer_material(layer, field.size, &rel),
                None => self.default_material(),
            };
            parts.push((i, material));
        }
        let object = self.soup.objects.len() as u32;
        self.soup.objects.push(Object {
            name: self.path(go),
            source: rel.clone(),
            layer: crate::layer::layer(&g.objs[go].body),
            cast_shadows: match body.i64_at("m_ShadowCastingMode") {
                Some(0) => CastShadows::Off,
                Some(2) => CastShadows::TwoSided,
                Some(3) => CastShadows::ShadowsOnly,
                _ => CastShadows::On,
            },
            receive_shadows: true,
        });
        let origin = format!("terrain layers of {rel}");
        self.material_origins
            .push(parts.iter().map(|&(_, m)| (m, origin.clone())).collect());
        self.placements.push(mesh, world, parts, object);
        Ok(())
    }

    fn warn(&mut self, line: String) {
        self.soup.warnings.push(line);
    }

    /// The layers in the splat maps' order, TerrainLayer assets read; a missing asset is
    /// None, with a warning.
    fn terrain_layers(&mut self, refs: &LayerRefs, what: &str) -> Vec<Option<Layer>> {
        let guids = match refs {
            LayerRefs::Inline(layers) => {
                // A splat prototype has no name of its own: its texture's file names it.
                let project = self.g.project;
                let named = |mut l: Layer| {
                    let file = l.texture.as_deref().and_then(|g| project.resolve(g));
                    if let Some(stem) = file.and_then(|f| f.file_stem()) {
                        l.name = stem.to_string_lossy().into_owned();
                    }
                    Some(l)
                };
                return layers.iter().cloned().map(named).collect();
            }
            LayerRefs::Assets(guids) => guids,
        };
        let mut layers = Vec::new();
        for guid in guids {
            let Some(guid) = guid else {
                layers.push(None);
                continue;
            };
            let Some(path) = self.g.project.resolve(guid).cloned() else {
                self.warn(format!(
                    "{what}: terrain layer GUID {guid} is not in the project; left out"
                ));
                layers.push(None);
                continue;
            };
            let rel = self.g.project.rel(&path);
            let layer = std::fs::read_to_string(&path)
                .ok()
                .and_then(|t| layer_asset(&t, &rel));
            if layer.is_none() {
                self.warn(format!("{what}: {rel} is not a TerrainLayer; left out"));
            }
            layers.push(layer);
        }
        layers
    }

    /// A warning naming every layer of a terrain with several, and the share `coverage`
    /// gives each.
    fn warn_layers(&mut self, layers: &[Option<Layer>], coverage: &[f64], what: &str) {
        if layers.len() > 1 {
            let shares: Vec<String> = layers
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    let name = l.as_ref().map_or("(missing)", |l| l.name.as_str());
                    match coverage.get(i) {
                        Some(c) => format!("'{name}' {:.0} %", c * 100.0),
                        None => format!("'{name}'"),
                    }
                })
                .collect();
            let rule = if coverage.is_empty() {
                "its splat maps are not readable, so it is drawn with the first layer"
            } else {
                "each cell is drawn with the layer that weighs most at its centre, not blended"
            };
            self.warn(format!(
                "{what}: {} terrain layers ({}); {rule}",
                layers.len(),
                shares.join(", ")
            ));
        }
    }

    /// Layer `layer` as the Standard material it shades like, its texture tiled over a
    /// terrain of `size` as the layer tiles it.
    fn layer_material(&mut self, layer: &Layer, size: Vec3, rel: &str) -> u32 {
        let source = format!("{rel}#layer:{}", layer.name);
        if let Some(&i) = self.materials.get(&source) {
            return i;
        }
        let tile = layer.tile_size.max(Vec2::splat(1e-3));
        let scale = Vec2::new(size.x, size.z) / tile;
        let offset = layer.tile_offset / tile;
        // Found, imported and tiled as a Standard material's albedo map is.
        let slot = layer.texture.as_ref().map(|guid| TextureSlot {
            property: "_MainTex".into(),
            guid: guid.clone(),
            tiling: Tiling {
                scale: scale.to_array(),
                offset: offset.to_array(),
            },
        });
        let albedo_map = slot.and_then(|slot| self.albedo(&slot, &source));
        // Unity's defaults stand in for properties that are not numbers.
        let default = Material::unity_default();
        let (metallic, smoothness) = if layer.metallic.is_finite() && layer.smoothness.is_finite() {
            (
                layer.metallic.clamp(0.0, 1.0),
                layer.smoothness.clamp(0.0, 1.0),
            )
        } else {
            (default.metallic, default.smoothness)
        };
        let m = Material {
            name: layer.name.clone(),
            source: source.clone(),
            metallic,
            smoothness,
            albedo_map,
            ..default
        };
        self.add_material(source, || m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::serialized::tests::{check_fuzz_seed, file, ObjSpec, TypeSpec, ALIGN, GUID_TEXT, W};

    /// A TerrainData of `resolution`² heights (`heights`), spacing (2, 50, 4), with one
    /// layer: a TerrainLayer asset (the only external) when `assets`, else (the layout
    /// before Unity 2018.3) a splat prototype whose texture is that external.
    ///
    /// `alpha`, when given, is one splat map of 2×1 texels: its texture format and image
    /// data. `holes`, when not empty, is the heightmap's `m_Holes`.
    fn terrain_data(
        version: u32,
        resolution: i32,
        heights: &[i16],
        assets: bool,
        alpha: Option<(i32, &[u8])>,
        holes: &[u8],
    ) -> Vec<u8> {
        let mut n = vec![(0, "TerrainData", "Base", -1, 0, 0)];
        n.extend([
            (1, "SplatDatabase", "m_SplatDatabase", -1, 0, 0),
            (
                2,
                "vector",
                if assets {
                    "m_TerrainLayers"
                } else {
                    "m_Splats"
                },
                -1,
                0,
                0,
            ),
            (3, "Array", "Array", -1, 1, 0),
            (4, "int", "size", 4, 0, 0),
        ]);
        if assets {
            n.extend([
                (4, "PPtr<TerrainLayer>", "data", 12, 0, 0),
                (5, "int", "m_FileID", 4, 0, 0),
                (5, "SInt64", "m_PathID", 8, 0, 0),
            ]);
        } else {
            n.extend([
                (4, "SplatPrototype", "data", -1, 0, 0),
                (5, "PPtr<Texture2D>", "texture", 12, 0, 0),
                (6, "int", "m_FileID", 4, 0, 0),
                (6, "SInt64", "m_PathID", 8, 0, 0),
                (5, "Vector2f", "tileSize", 8, 0, 0),
                (6, "float", "x", 4, 0, 0),
                (6, "float", "y", 4, 0, 0),
                (5, "float", "smoothness", 4, 0, 0),
            ]);
        }
        if alpha.is_some() {
            n.extend([
                (2, "vector", "m_AlphaTextures", -1, 0, 0),
                (3, "Array", "Array", -1, 1, 0),
                (4, "int", "size", 4, 0, 0),
                (4, "PPtr<Texture2D>", "data", 12, 0, 0),
                (5, "int", "m_FileID", 4, 0, 0),
                (5, "SInt64", "m_PathID", 8, 0, 0),
            ]);
        }
        n.extend([
            (1, "Heightmap", "m_Heightmap", -1, 0, 0),
            (2, "vector", "m_Heights", -1, 0, 0),
            (3, "Array", "Array", -1, 1, ALIGN),
            (4, "int", "size", 4, 0, 0),
            (4, "SInt16", "data", 2, 0, 0),
        ]);
        if !holes.is_empty() {
            n.extend([
                (2, "vector", "m_Holes", -1, 0, 0),
                (3, "Array", "Array", -1, 1, ALIGN),
                (4, "int", "size", 4, 0, 0),
                (4, "UInt8", "data", 1, 0, 0),
            ]);
        }
        n.extend([
            (
                2,
                "int",
                if assets { "m_Resolution" } else { "m_Width" },
                4,
                0,
                0,
            ),
            (2, "Vector3f", "m_Scale", 12, 0, 0),
            (3, "float", "x", 4, 0, 0),
            (3, "float", "y", 4, 0, 0),
            (3, "float", "z", 4, 0, 0),
        ]);
        let mut w = W::new(false);
        w.i32(1);
        w.i32(1);
        w.i64(if assets { 8574412962073106934 } else { 2800000 });
        if !assets {
            w.f32(7.0);
            w.f32(3.0);
            w.f32(0.25);
        }
        if alpha.is_some() {
            w.i32(1);
            w.i32(0);
            w.i64(2);
        }
        w.i32(heights.len() as i32);
        for &h in heights {
            w.i16(h);
        }
        w.align();
        if !holes.is_empty() {
            w.i32(holes.len() as i32);
            for &b in holes {
                w.u8(b);
            }
            w.align();
        }
        w.i32(resolution);
        for v in [2.0, 50.0, 4.0] {
            w.f32(v);
        }
        let mut types = vec![TypeSpec {
            class_id: TERRAIN_DATA,
            nodes: n,
        }];
        let mut objects = vec![ObjSpec {
            path_id: 15600000,
            type_index: 0,
            data: w.buf,
        }];
        if let Some((format, image)) = alpha {
            types.push(TypeSpec {
                class_id: 28,
                nodes: vec![
                    (0, "Texture2D", "Base", -1, 0, 0),
                    (1, "int", "m_Width", 4, 0, 0),
                    (1, "int", "m_Height", 4, 0, 0),
                    (1, "int", "m_TextureFormat", 4, 0, 0),
                    (1, "TypelessData", "image data", -1, 1, ALIGN),
                    (2, "int", "size", 4, 0, 0),
                    (2, "UInt8", "data", 1, 0, 0),
                ],
            });
            let mut t = W::new(false);
            for v in [2, 1, format, image.len() as i32] {
                t.i32(v);
            }
            t.buf.extend_from_slice(image);
            t.align();
            objects.push(ObjSpec {
                path_id: 2,
                type_index: 1,
                data: t.buf,
            });
        }
        file(version, false, true, &types, &objects)
    }

    #[test]
    fn terrain_data_reads_heights_size_and_layers_in_both_layouts() {
        let heights = [0, 16383, 32766, -5, 32767, 0, 0, 0, 100];
        for (version, assets) in [(22, true), (17, true), (17, false)] {
            let bytes = terrain_data(version, 3, &heights, assets, None, &[]);
            let file = SerializedFile::parse(bytes, "Assets/T.asset").unwrap();
            let TerrainData {
                field,
                layers,
                splat,
                holes,
                trees,
            } = read(&file, 15600000).unwrap();
            assert_eq!(trees, Trees::default());
            assert!(holes.is_empty());
            assert!(splat.is_none(), "no splat maps");
            assert_eq!(field.resolution, 3);
            assert_eq!(field.size, Vec3::new(4.0, 50.0, 8.0));
            let expect = [
                0.0,
                16383.0 / 32766.0,
                1.0,
                0.0,
                1.0,
                0.0,
                0.0,
                0.0,
                100.0 / 32766.0,
            ];
            assert_eq!(field.heights, expect);
            match layers {
                LayerRefs::Assets(guids) => {
                    assert!(assets);
                    assert_eq!(guids, [Some(GUID_TEXT.to_string())]);
                }
                LayerRefs::Inline(splats) => {
                    assert!(!assets);
                    assert_eq!(splats.len(), 1);
                    assert_eq!(splats[0].texture.as_deref(), Some(GUID_TEXT));
                    assert_eq!(splats[0].tile_size, Vec2::new(7.0, 3.0));
                    assert_eq!(splats[0].smoothness, 0.25);
                }
            }
        }
    }

    #[test]
    fn splat_maps_are_read_in_either_byte_order_from_their_first_mip_level() {
        // Left texel: layer 0 (R) full; right texel: layer 1 (G) 55, layer 3 (A) 200.
        // Then a 1×1 mip level that must not count.
        let argb = [0, 255, 0, 0, 200, 0, 55, 0, 9, 9, 9, 9];
        let rgba = [255, 0, 0, 0, 0, 55, 0, 200, 9, 9, 9, 9];
        for (format, image) in [(5, argb), (4, rgba)] {
            let bytes = terrain_data(22, 3, &[0; 9], true, Some((format, &image)), &[]);
            let file = SerializedFile::parse(bytes, "Assets/T.asset").unwrap();
            let splat = read(&file, 15600000).unwrap().splat.expect("a splat map");
            assert_eq!(splat.maps[0].texels, [[255, 0, 0, 0], [0, 55, 0, 200]]);
            assert_eq!(splat.weight(3, 0.9, 0.5), 200);
            let c = splat.coverage();
            assert_eq!(c, [0.5, 55.0 / 510.0, 0.0, 200.0 / 510.0]);
        }
        // Another format is not read.
        let bytes = terrain_data(22, 3, &[0; 9], true, Some((10, &[0; 12])), &[]);
        let file = SerializedFile::parse(bytes, "Assets/T.asset").unwrap();
        assert!(read(&file, 15600000).unwrap().splat.is_none());
    }

    #[test]
    fn a_heightmap_that_does_not_match_its_resolution_is_refused() {
        let bytes = terrain_data(22, 4, &[0; 9], true, None, &[]);
        let file = SerializedFile::parse(bytes, "Assets/T.asset").unwrap();
        let err = read(&file, 15600000).err().unwrap();
        assert_eq!(err, "m_Heights holds 9 samples for a resolution of 4");
    }

    fn field(resolution: usize, size: Vec3, height: impl Fn(usize, usize) -> f32) -> Heightfield {
        let heights = (0..resolution * resolution)
            .map(|i| height(i % resolution, i / resolution))
            .collect();
        Heightfield {
            resolution,
            heights,
            size,
        }
    }

    #[test]
    fn the_grid_spans_the_terrain_and_faces_up() {
        // 3×3 samples over 10 m × 20 m, 4 m high, raised along z.
        let f = field(3, Vec3::new(10.0, 4.0, 20.0), |_, z| z as f32 / 2.0);
        let m = f.mesh(1, |_, _| Some(0));
        assert_eq!(m.positions.len(), 9);
        assert_eq!(m.submeshes[0].len(), 8);
        assert_eq!(m.positions[0], Vec3::ZERO);
        assert_eq!(m.positions[2], Vec3::new(10.0, 0.0, 0.0));
        assert_eq!(m.positions[8], Vec3::new(10.0, 4.0, 20.0));
        assert_eq!(m.uvs[5], Vec2::new(1.0, 0.5));
        // Slope 4 m over 20 m along z: the normal leans back toward −z.
        let expect = Vec3::new(0.0, 1.0, -0.2).normalize();
        for n in &m.normals {
            assert!(n.abs_diff_eq(expect, 1e-6), "{n}");
        }
        // Unity's front faces (clockwise seen from the front) face the normal: in Unity's
        // left-handed space cross(b − a, c − a) points out of the front.
        for t in &m.submeshes[0] {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n = (b - a).cross(c - a).normalize();
            assert!(n.abs_diff_eq(expect, 1e-6), "{t:?}: {n}");
        }
    }

    #[test]
    fn each_cell_goes_to_the_part_its_centre_picks_and_splat_weights_come_from_the_nearest_texel() {
        // 5×5 samples, 4×4 cells; cells whose centre lies left of u = 0.5 go to part 1.
        let f = field(5, Vec3::new(4.0, 1.0, 4.0), |_, _| 0.0);
        let m = f.mesh(2, |u, v| {
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
            // The far right corner cell is a hole.
            (u < 0.75 || v < 0.75).then_some(usize::from(u < 0.5))
        });
        assert_eq!((m.submeshes[0].len(), m.submeshes[1].len()), (14, 16));
        for t in &m.submeshes[1] {
            assert!(t.iter().all(|&i| m.positions[i as usize].x <= 2.0), "{t:?}");
        }
        let corner = |t: &[u32; 3]| {
            t.iter()
                .all(|&i| m.positions[i as usize].x.min(m.positions[i as usize].z) >= 3.0)
        };
        assert!(!m.submeshes[0].iter().any(corner));
        // A 2×1 map: layer 0 (R) on the left texel, layer 5 (second map's G) on the right.
        let splat = Splat {
            maps: vec![
                SplatMap {
                    width: 2,
                    height: 1,
                    texels: vec![[255, 0, 0, 0], [0, 0, 0, 0]],
                },
                SplatMap {
                    width: 2,
                    height: 1,
                    texels: vec![[0, 0, 0, 0], [0, 255, 0, 0]],
                },
            ],
        };
        assert_eq!(splat.weight(0, 0.2, 0.9), 255);
        assert_eq!(splat.weight(0, 0.7, 0.9), 0);
        assert_eq!(splat.weight(5, 0.7, 0.0), 255);
        assert_eq!(splat.weight(5, 1.0, 1.0), 255);
        assert_eq!(splat.weight(9, 0.5, 0.5), 0);
        assert_eq!(splat.coverage(), [0.5, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0]);
    }

    #[test]
    fn a_large_heightmap_is_drawn_from_every_kth_sample_to_its_far_edge() {
        // 2,050 samples a side (2,049 cells): every 3rd sample, 684 cells, the last one
        // shorter.
        let res = 2050;
        let f = field(res, Vec3::new(2049.0, 1.0, 2049.0), |x, z| {
            ((x + z) % 2) as f32
        });
        let m = f.mesh(1, |_, _| Some(0));
        let n = 2049usize.div_ceil(3) + 1;
        assert_eq!(m.positions.len(), n * n);
        assert_eq!(m.submeshes[0].len(), 2 * (n - 1) * (n - 1));
        assert_eq!(m.positions[1], Vec3::new(3.0, 1.0, 0.0));
        assert_eq!(m.positions[n - 1].x, 2049.0);
        assert_eq!(m.positions[n * n - 1], Vec3::new(2049.0, 0.0, 2049.0));
    }

    /// A scene of one terrain of TerrainData `data` at (10, 1, 20), turned and scaled
    /// (which a terrain ignores), with one layer 'Grass' tiled 2 m × 4 m from 1 m, its
    /// shadows off.
    fn convert_terrain(data: &[u8]) -> formats::Soup {
        let dir = tempfile::tempdir().unwrap();
        let assets = dir.path().join("Assets");
        std::fs::create_dir_all(&assets).unwrap();
        let put = |name: &str, bytes: &[u8], guid: &str| {
            std::fs::write(assets.join(name), bytes).unwrap();
            let meta = format!("fileFormatVersion: 2\nguid: {guid}\n");
            std::fs::write(assets.join(format!("{name}.meta")), meta).unwrap();
        };
        put("T.asset", data, "aaaa0000aaaa0000aaaa0000aaaa0000");
        let layer = "%YAML 1.1\n--- !u!1953259897 &8574412962073106934\nTerrainLayer:\n  m_Name: Grass\n  m_DiffuseTexture: {fileID: 2800000, guid: bbbb0000bbbb0000bbbb0000bbbb0000, type: 3}\n  m_TileSize: {x: 2, y: 4}\n  m_TileOffset: {x: 1, y: 0}\n  m_Smoothness: 0.25\n";
        put("Grass.terrainlayer", layer.as_bytes(), GUID_TEXT);
        let mut png = std::io::Cursor::new(Vec::new());
        image::RgbaImage::from_pixel(2, 2, image::Rgba([0, 255, 0, 255]))
            .write_to(&mut png, image::ImageFormat::Png)
            .unwrap();
        put("g.png", png.get_ref(), "bbbb0000bbbb0000bbbb0000bbbb0000");
        let scene = "%YAML 1.1\n--- !u!1 &10\nGameObject:\n  m_Component:\n  - component: {fileID: 11}\n  m_Name: Ground\n  m_IsActive: 1\n--- !u!4 &11\nTransform:\n  m_GameObject: {fileID: 10}\n  m_LocalRotation: {x: 0, y: 0.7071068, z: 0, w: 0.7071068}\n  m_LocalPosition: {x: 10, y: 1, z: 20}\n  m_LocalScale: {x: 2, y: 2, z: 2}\n  m_Father: {fileID: 0}\n--- !u!218 &12\nTerrain:\n  m_GameObject: {fileID: 10}\n  m_Enabled: 1\n  m_TerrainData: {fileID: 15600000, guid: aaaa0000aaaa0000aaaa0000aaaa0000, type: 2}\n  m_ShadowCastingMode: 0\n";
        put(
            "s.unity",
            scene.as_bytes(),
            "cccc0000cccc0000cccc0000cccc0000",
        );
        crate::convert_report(&assets.join("s.unity"), &crate::Options::default())
            .unwrap()
            .soup
    }

    #[test]
    fn a_scene_terrain_lies_along_the_axes_from_its_position_with_its_layer_tiled() {
        let heights = [0, 0, 0, 0, 32766, 0, 0, 0, 0];
        let soup = &convert_terrain(&terrain_data(22, 3, &heights, true, None, &[]));
        assert_eq!(soup.triangles.len(), 8, "{:?}", soup.warnings);
        assert_eq!(soup.objects[0].name, "Ground");
        assert_eq!(soup.objects[0].cast_shadows, CastShadows::Off);
        // Unity x is negated in the soup; 4 m × 8 m from (10, 1, 20), the middle sample
        // at the full 50 m.
        let pos = |i: usize| soup.positions[i];
        let mut xs: Vec<f32> = (0..soup.positions.len()).map(|i| pos(i).x).collect();
        xs.sort_by(f32::total_cmp);
        assert_eq!((xs[0], xs[xs.len() - 1]), (-14.0, -10.0));
        assert!((0..9).any(|i| pos(i) == Vec3::new(-12.0, 51.0, 24.0)));
        assert!((0..9).any(|i| pos(i) == Vec3::new(-14.0, 1.0, 28.0)));
        let m = &soup.materials[0];
        assert_eq!((m.name.as_str(), m.smoothness), ("Grass", 0.25));
        let map = m.albedo_map.expect("the layer's texture");
        // 4 m / 2 m and 8 m / 4 m repeats; an offset of 1 m is half a 2 m tile.
        assert_eq!(map.tiling.scale, [2.0, 2.0]);
        assert_eq!(map.tiling.offset, [0.5, 0.0]);
        assert_eq!(soup.textures.len(), 1);
        assert_eq!(
            soup.warnings,
            ["Assets/s.unity: no enabled camera renders to the display; Unity's default camera used"]
        );
    }

    #[test]
    fn painted_holes_cut_their_cells_and_a_mask_of_the_wrong_size_is_said() {
        // 2×2 cells; the hole is the cell at x 1, z 0: 2–4 m along x (−2 to −4 in the
        // soup), 0–4 m along z, from (10, 1, 20).
        let data = terrain_data(22, 3, &[0; 9], true, None, &[255, 0, 255, 255]);
        let soup = convert_terrain(&data);
        assert_eq!(soup.triangles.len(), 6, "{:?}", soup.warnings);
        for t in &soup.triangles {
            let centre = t.iter().map(|&i| soup.positions[i as usize]).sum::<Vec3>() / 3.0;
            let in_hole = (-14.0..-12.0).contains(&centre.x) && (20.0..24.0).contains(&centre.z);
            assert!(!in_hole, "{centre}");
        }
        assert_eq!(soup.warnings.len(), 1, "{:?}", soup.warnings);
        let soup = convert_terrain(&terrain_data(22, 3, &[0; 9], true, None, &[0; 3]));
        assert_eq!(soup.triangles.len(), 8);
        assert_eq!(
            soup.warnings[0],
            "Assets/s.unity: object 'Ground' (fileID 10): its holes are not cut: m_Holes holds 3 bytes for 2×2 cells"
        );
    }

    /// A TerrainData with a splat map and holes seeds the `unity_serialized` fuzz target.
    #[test]
    fn fuzz_seed_with_splat_map_and_holes_is_current() {
        let image = [255, 0, 0, 0, 0, 255, 0, 0];
        let holes = [255, 0, 255, 255];
        let data = terrain_data(22, 3, &[0; 9], true, Some((4, &image)), &holes);
        check_fuzz_seed("seed-terrain-holes.bin", &data);
    }
}
