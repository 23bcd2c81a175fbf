//! Trees painted on a terrain: each tree instance of a Terrain's TerrainData becomes an
//! instance of its prototype's prefab or model, hung under the terrain's Transform so
//! that it is drawn, culled and named like any other object of the scene.
//!
//! A tree stands at its instance's position within the terrain (a share of the terrain's
//! size on each axis, its height included), turned about the vertical axis by the
//! instance's rotation and scaled by its width (x and z) and height (y) times the
//! prototype root's own scale. Like the terrain's heightmap, its trees follow the
//! terrain's position alone: Unity ignores a terrain's rotation and scale. The root's own
//! position and rotation are not used.

use crate::docs;
use crate::graph::{is_transform, Graph};
use crate::reference::Ref;
use crate::terrain::{TreeInstance, Trees};
use crate::yaml::Node;
use glam::{Quat, Vec3};

impl Graph<'_> {
    /// Plant the trees of every enabled Terrain that draws them.
    pub(crate) fn plant_trees(&mut self) {
        let terrains: Vec<usize> = (0..self.objs.len())
            .filter(|&i| {
                let o = &self.objs[i];
                o.class == docs::TERRAIN
                    && !o.removed
                    && o.body.i64_at("m_Enabled") != Some(0)
                    && o.body.i64_at("m_DrawTreesAndFoliage") != Some(0)
            })
            .collect();
        for t in terrains {
            self.plant(t);
        }
    }

    /// The trees of Terrain component `terrain`. A TerrainData that cannot be read is
    /// left to the terrain's own conversion, which says why.
    fn plant(&mut self, terrain: usize) {
        let o = &self.objs[terrain];
        let Some(go) = o.go else { return };
        let Some(tf) = (0..self.objs.len())
            .find(|&i| is_transform(self.objs[i].class) && self.objs[i].go == Some(go))
        else {
            return;
        };
        let r = Ref::read(o.body.get("m_TerrainData"), o.file);
        let Some(path) = r
            .guid
            .as_deref()
            .filter(|_| r.file_id != 0)
            .and_then(|g| self.project.resolve(g))
            .cloned()
        else {
            return;
        };
        let parsed = self.project.terrain_data(&path, r.file_id);
        let Ok(data) = parsed.as_ref() else {
            return;
        };
        let Trees {
            prototypes,
            instances,
        } = &data.trees;
        let scene = self
            .files
            .get(o.file)
            .map(|f| self.project.rel(&f.path))
            .unwrap_or_default();
        let name = self.objs[go].body.str_at("m_Name").unwrap_or("?");
        let who = format!(
            "{scene}: terrain '{name}' (fileID {})",
            self.objs[go].file_id
        );
        let size = data.field.size;
        // A place beyond f32's range (a damaged file) would make the tree's transform
        // infinite.
        let (instances, far): (Vec<&TreeInstance>, Vec<&TreeInstance>) = instances
            .iter()
            .partition(|t| (t.position * size).is_finite());
        if !far.is_empty() {
            self.warnings.push(format!(
                "{who}: {} not drawn: placed beyond the range of 32-bit floats",
                count(far.len())
            ));
        }
        for (p, guid) in prototypes.iter().enumerate() {
            let mine: Vec<&TreeInstance> = instances
                .iter()
                .copied()
                .filter(|t| t.prototype == p)
                .collect();
            if mine.is_empty() {
                continue;
            }
            let what = format!("{who}: tree prototype {p}");
            let Some(guid) = guid else {
                self.warnings.push(format!(
                    "{what} has no prefab: {} not drawn",
                    count(mine.len())
                ));
                continue;
            };
            for (k, tree) in mine.iter().enumerate() {
                let (_, roots) = self.instance_of(guid, &what);
                if roots.is_empty() {
                    // Said once, by the first instance: every other would say the same.
                    if mine.len() > 1 {
                        self.warnings.push(format!(
                            "{what}: {} of its {} trees are not drawn",
                            mine.len() - k,
                            mine.len()
                        ));
                    }
                    break;
                }
                for root in roots {
                    self.stand(root, tf, tree, size);
                }
            }
        }
        let unknown = instances
            .iter()
            .filter(|t| t.prototype >= prototypes.len())
            .count();
        if unknown > 0 {
            self.warnings.push(format!(
                "{who}: {} not drawn: no such prototype in the TerrainData (it has {})",
                count(unknown),
                prototypes.len()
            ));
        }
    }

    /// Stand root Transform `root` of a tree's objects as `tree` says, on the terrain
    /// whose Transform is `terrain` (of size `size`).
    fn stand(&mut self, root: usize, terrain: usize, tree: &TreeInstance, size: Vec3) {
        let o = &mut self.objs[root];
        o.father = Some(terrain);
        o.on_terrain = true;
        let scale = o
            .body
            .get("m_LocalScale")
            .and_then(Node::vec3)
            .unwrap_or(Vec3::ONE)
            * Vec3::new(tree.width, tree.height, tree.width);
        let rotation = Quat::from_rotation_y(tree.rotation);
        let vector = |v: &[f32]| {
            Node::Map(
                ["x", "y", "z", "w"]
                    .iter()
                    .zip(v)
                    .map(|(k, v)| (k.to_string(), Node::Scalar(v.to_string())))
                    .collect(),
            )
        };
        let Node::Map(kv) = &mut o.body else { return };
        kv.retain(|(k, _)| {
            !matches!(
                k.as_str(),
                "m_LocalPosition" | "m_LocalRotation" | "m_LocalScale"
            )
        });
        kv.push((
            "m_LocalPosition".into(),
            vector(&(tree.position * size).to_array()),
        ));
        kv.push(("m_LocalRotation".into(), vector(&rotation.to_array())));
        kv.push(("m_LocalScale".into(), vector(&scale.to_array())));
    }
}

/// "1 tree", "3 trees".
fn count(n: usize) -> String {
    if n == 1 {
        "1 tree".into()
    } else {
        format!("{n} trees")
    }
}

#[cfg(test)]
mod tests {
    use crate::serialized::tests::{check_fuzz_seed, file, ObjSpec, TypeSpec, ALIGN, GUID_TEXT, W};
    use glam::Vec3;

    /// A flat TerrainData 8 m × 40 m × 16 m (2² samples) with one tree prototype (the
    /// file's external) and trees at `trees`: (position, width, height, rotation,
    /// prototype).
    fn terrain_data(trees: &[(Vec3, f32, f32, f32, i32)]) -> Vec<u8> {
        let mut n = vec![(0, "TerrainData", "Base", -1, 0, 0)];
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
            (2, "vector", "m_TreeInstances", -1, 0, 0),
            (3, "Array", "Array", -1, 1, 0),
            (4, "int", "size", 4, 0, 0),
            (4, "TreeInstance", "data", 44, 0, 0),
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
        let mut w = W::new(false);
        w.i32(1);
        w.i32(1);
        w.i64(100);
        w.f32(0.0);
        w.i32(trees.len() as i32);
        for &(p, width, height, rotation, prototype) in trees {
            for v in [p.x, p.y, p.z, width, height, rotation] {
                w.f32(v);
            }
            w.u32(u32::MAX);
            w.u32(u32::MAX);
            w.i32(prototype);
        }
        w.i32(4);
        for _ in 0..4 {
            w.i16(0);
        }
        w.align();
        w.i32(2);
        for v in [8.0, 40.0, 16.0] {
            w.f32(v);
        }
        let types = [TypeSpec {
            class_id: 156,
            nodes: n,
        }];
        let objects = [ObjSpec {
            path_id: 15600000,
            type_index: 0,
            data: w.buf,
        }];
        file(22, false, true, &types, &objects)
    }

    /// A tree prefab: the root 'Pine' (its position and rotation unused, its scale 2)
    /// and under it a unit cube 'Trunk', 1 m along x and 0.5 m up.
    const PINE: &str = "%YAML 1.1
--- !u!1 &100
GameObject:
  m_Component:
  - component: {fileID: 101}
  m_Name: Pine
  m_IsActive: 1
--- !u!4 &101
Transform:
  m_GameObject: {fileID: 100}
  m_LocalRotation: {x: 0, y: 0.7071068, z: 0, w: 0.7071068}
  m_LocalPosition: {x: 5, y: 5, z: 5}
  m_LocalScale: {x: 2, y: 2, z: 2}
  m_Father: {fileID: 0}
--- !u!1 &200
GameObject:
  m_Component:
  - component: {fileID: 201}
  - component: {fileID: 202}
  - component: {fileID: 203}
  m_Name: Trunk
  m_IsActive: 1
--- !u!4 &201
Transform:
  m_GameObject: {fileID: 200}
  m_LocalRotation: {x: 0, y: 0, z: 0, w: 1}
  m_LocalPosition: {x: 1, y: 0.5, z: 0}
  m_LocalScale: {x: 1, y: 1, z: 1}
  m_Father: {fileID: 101}
--- !u!33 &202
MeshFilter:
  m_GameObject: {fileID: 200}
  m_Mesh: {fileID: 10202, guid: 0000000000000000e000000000000000, type: 0}
--- !u!23 &203
MeshRenderer:
  m_GameObject: {fileID: 200}
  m_Enabled: 1
  m_Materials:
  - {fileID: 10303, guid: 0000000000000000f000000000000000, type: 0}
";

    /// A scene of one terrain, turned and scaled (which its trees ignore, as it does),
    /// with `terrain` as its Terrain component's last lines.
    fn scene(terrain: &str) -> String {
        format!("%YAML 1.1\n--- !u!1 &10\nGameObject:\n  m_Component:\n  - component: {{fileID: 11}}\n  m_Name: Ground\n  m_IsActive: 1\n--- !u!4 &11\nTransform:\n  m_GameObject: {{fileID: 10}}\n  m_LocalRotation: {{x: 0, y: 0.7071068, z: 0, w: 0.7071068}}\n  m_LocalPosition: {{x: 10, y: 1, z: 20}}\n  m_LocalScale: {{x: 2, y: 2, z: 2}}\n  m_Father: {{fileID: 0}}\n--- !u!218 &12\nTerrain:\n  m_GameObject: {{fileID: 10}}\n  m_TerrainData: {{fileID: 15600000, guid: aaaa0000aaaa0000aaaa0000aaaa0000, type: 2}}\n{terrain}")
    }

    /// Convert `scene` in a project of the terrain and, when `pine`, the prefab.
    fn convert(trees: &[(Vec3, f32, f32, f32, i32)], pine: bool, scene: &str) -> formats::Soup {
        let dir = tempfile::tempdir().unwrap();
        let assets = dir.path().join("Assets");
        std::fs::create_dir_all(&assets).unwrap();
        let put = |name: &str, bytes: &[u8], guid: &str| {
            std::fs::write(assets.join(name), bytes).unwrap();
            let meta = format!("fileFormatVersion: 2\nguid: {guid}\n");
            std::fs::write(assets.join(format!("{name}.meta")), meta).unwrap();
        };
        put(
            "T.asset",
            &terrain_data(trees),
            "aaaa0000aaaa0000aaaa0000aaaa0000",
        );
        if pine {
            put("Pine.prefab", PINE.as_bytes(), GUID_TEXT);
        }
        put(
            "s.unity",
            scene.as_bytes(),
            "cccc0000cccc0000cccc0000cccc0000",
        );
        let path = assets.join("s.unity");
        crate::convert_report(&path, &crate::Options::default())
            .unwrap()
            .soup
    }

    /// The bounds of soup object `object`'s triangles.
    fn bounds(soup: &formats::Soup, object: u32) -> (Vec3, Vec3) {
        let points = soup
            .triangles
            .iter()
            .zip(&soup.tri_object)
            .filter(|&(_, &o)| o == object)
            .flat_map(|(t, _)| t.map(|v| soup.positions[v as usize]));
        points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        })
    }

    #[test]
    fn a_tree_stands_at_its_place_on_the_terrain_turned_and_scaled() {
        // Half way across, a quarter of the height and of the depth; 1.5 wide, 0.5 high,
        // a quarter turn; and one tree of a prototype that does not exist.
        let trees = [
            (
                Vec3::new(0.5, 0.25, 0.25),
                1.5,
                0.5,
                std::f32::consts::FRAC_PI_2,
                0,
            ),
            (Vec3::new(0.1, 0.0, 0.1), 1.0, 1.0, 0.0, 3),
            (Vec3::new(1e38, 0.0, 0.1), 1.0, 1.0, 0.0, 0),
        ];
        let soup = convert(&trees, true, &scene(""));
        assert_eq!(soup.objects.len(), 2, "{:?}", soup.warnings);
        assert_eq!(soup.objects[1].name, "Ground/Pine/Trunk");
        assert_eq!(soup.triangles.len(), 2 + 12);
        // The tree's root at (10, 1, 20) + (0.5·8, 0.25·40, 0.25·16) = (14, 11, 24). The
        // cube's centre, (1, 0.5, 0) in the root, scaled by 2 × (1.5, 0.5, 1.5) to
        // (3, 0.5, 0) and turned a quarter (+x to −z): (14, 11.5, 21); its half sizes
        // (1.5, 0.5, 1.5). The soup negates Unity's x.
        let (lo, hi) = bounds(&soup, 1);
        let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-4;
        assert!(close(lo, Vec3::new(-15.5, 11.0, 19.5)), "{lo}");
        assert!(close(hi, Vec3::new(-12.5, 12.0, 22.5)), "{hi}");
        assert_eq!(
            soup.warnings,
            [
                "Assets/s.unity: terrain 'Ground' (fileID 10): 1 tree not drawn: placed beyond the range of 32-bit floats",
                "Assets/s.unity: terrain 'Ground' (fileID 10): 1 tree not drawn: no such prototype in the TerrainData (it has 1)",
                "Assets/s.unity: no enabled camera renders to the display; Unity's default camera used",
            ]
        );
    }

    #[test]
    fn trees_are_not_drawn_when_the_terrain_does_not_draw_them_and_a_missing_prefab_is_said_once() {
        let tree = (Vec3::new(0.5, 0.0, 0.5), 1.0, 1.0, 0.0, 0);
        for lines in ["  m_DrawTreesAndFoliage: 0\n", "  m_Enabled: 0\n"] {
            let soup = convert(&[tree; 3], true, &scene(lines));
            let drawn = if lines.contains("Enabled") { 0 } else { 2 };
            assert_eq!(soup.triangles.len(), drawn, "{lines}");
        }
        let soup = convert(&[tree; 3], false, &scene(""));
        assert_eq!(soup.triangles.len(), 2);
        let what = "Assets/s.unity: terrain 'Ground' (fileID 10): tree prototype 0";
        assert_eq!(
            soup.warnings[..2],
            [
                format!("{what}: source GUID {GUID_TEXT} is not in the project (missing asset or package); skipped"),
                format!("{what}: 3 of its 3 trees are not drawn"),
            ]
        );
    }

    /// A TerrainData with trees seeds the `unity_serialized` fuzz target, which reads
    /// every TerrainData it finds.
    #[test]
    fn fuzz_seed_with_trees_is_current() {
        let tree = (Vec3::new(0.5, 0.25, 0.25), 1.5, 0.5, 1.0, 0);
        check_fuzz_seed("seed-terrain-trees.bin", &terrain_data(&[tree; 2]));
    }
}
