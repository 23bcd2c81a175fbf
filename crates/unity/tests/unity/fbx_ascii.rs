//! A tiny ASCII FBX 7.4 writer for tests: global axes and unit, Model nodes with their
//! transform properties, Mesh geometry (polygons, optional normals, per-polygon material
//! indices) and materials, connected the way exporters connect them.
#![allow(dead_code)]

use std::fmt::Write;

pub struct Fbx {
    /// UpAxis, UpAxisSign, FrontAxis, FrontAxisSign, CoordAxis, CoordAxisSign.
    pub axes: [i32; 6],
    pub unit_scale_factor: f64,
    pub nodes: Vec<Node>,
    pub materials: Vec<(String, [f64; 3])>,
    /// Skin deformers on mesh nodes.
    pub skins: Vec<SkinSpec>,
    /// Mesh nodes (indices in [`Fbx::nodes`]) given one blend shape that lifts vertex 0.
    pub blend_shapes: Vec<usize>,
}

pub struct SkinSpec {
    /// Index in [`Fbx::nodes`] of the mesh node.
    pub mesh: usize,
    pub clusters: Vec<Cluster>,
}

pub struct Cluster {
    /// Index in [`Fbx::nodes`] of the bone.
    pub bone: usize,
    /// (control point, weight).
    pub weights: Vec<(u32, f64)>,
    /// `Transform`: mesh space → bone space at bind time (what exporters write: the
    /// bone's global matrix inverted times the mesh's), column-major.
    pub transform: [f64; 16],
    /// `TransformLink`: the bone's global matrix at bind time, column-major.
    pub link: [f64; 16],
}

pub struct Node {
    pub name: String,
    /// Index in [`Fbx::nodes`]; `None` for a child of the file's root.
    pub parent: Option<usize>,
    /// FBX property name → three values ("Lcl Translation", "PreRotation", ...).
    pub props: Vec<(&'static str, [f64; 3])>,
    pub mesh: Option<Geometry>,
    /// Indices into [`Fbx::materials`], in the node's slot order.
    pub materials: Vec<usize>,
    /// A skeleton joint (`LimbNode`) rather than an empty (`Null`).
    pub limb: bool,
}

pub struct Geometry {
    pub vertices: Vec<[f64; 3]>,
    pub polygons: Vec<Vec<u32>>,
    /// Per polygon-vertex normals (`ByPolygonVertex`, `Direct`), if any.
    pub normals: Option<Vec<[f64; 3]>>,
    /// Per polygon material slot (`ByPolygon`), if any.
    pub poly_materials: Option<Vec<u32>>,
}

impl Node {
    pub fn new(name: &str, parent: Option<usize>) -> Node {
        Node {
            name: name.into(),
            parent,
            props: vec![],
            mesh: None,
            materials: vec![],
            limb: false,
        }
    }
    pub fn limb(mut self) -> Node {
        self.limb = true;
        self
    }
    pub fn prop(mut self, name: &'static str, v: [f64; 3]) -> Node {
        self.props.push((name, v));
        self
    }
    pub fn mesh(mut self, g: Geometry) -> Node {
        self.mesh = Some(g);
        self
    }
    pub fn materials(mut self, m: &[usize]) -> Node {
        self.materials = m.to_vec();
        self
    }
}

impl Geometry {
    pub fn new(vertices: &[[f64; 3]], polygons: &[&[u32]]) -> Geometry {
        Geometry {
            vertices: vertices.to_vec(),
            polygons: polygons.iter().map(|p| p.to_vec()).collect(),
            normals: None,
            poly_materials: None,
        }
    }
}

impl Default for Fbx {
    fn default() -> Fbx {
        Fbx {
            axes: [1, 1, 2, 1, 0, 1],
            unit_scale_factor: 1.0,
            nodes: vec![],
            materials: vec![],
            skins: vec![],
            blend_shapes: vec![],
        }
    }
}

fn list<T: std::fmt::Display>(v: impl IntoIterator<Item = T>) -> (usize, String) {
    let items: Vec<String> = v.into_iter().map(|x| x.to_string()).collect();
    (items.len(), items.join(","))
}

impl Fbx {
    pub fn text(&self) -> String {
        let mut s = String::new();
        s.push_str("; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n");
        s.push_str("GlobalSettings:  {\n\tVersion: 1000\n\tProperties70:  {\n");
        let names = [
            "UpAxis",
            "UpAxisSign",
            "FrontAxis",
            "FrontAxisSign",
            "CoordAxis",
            "CoordAxisSign",
        ];
        for (n, v) in names.iter().zip(self.axes) {
            writeln!(s, "\t\tP: \"{n}\", \"int\", \"Integer\", \"\",{v}").unwrap();
        }
        for n in ["UnitScaleFactor", "OriginalUnitScaleFactor"] {
            writeln!(
                s,
                "\t\tP: \"{n}\", \"double\", \"Number\", \"\",{}",
                self.unit_scale_factor
            )
            .unwrap();
        }
        s.push_str("\t}\n}\nObjects:  {\n");
        let mut conns = String::new();
        for (i, n) in self.nodes.iter().enumerate() {
            let id = 1000 + i as i64;
            let kind = match (&n.mesh, n.limb) {
                (Some(_), _) => "Mesh",
                (None, true) => "LimbNode",
                (None, false) => "Null",
            };
            writeln!(s, "\tModel: {id}, \"Model::{}\", \"{kind}\" {{", n.name).unwrap();
            s.push_str("\t\tVersion: 232\n\t\tProperties70:  {\n");
            for (p, v) in &n.props {
                let (ty, a, b) = if p.starts_with("Lcl ") {
                    (*p, "", "A")
                } else {
                    ("Vector3D", "Vector", "")
                };
                writeln!(
                    s,
                    "\t\t\tP: \"{p}\", \"{ty}\", \"{a}\", \"{b}\",{},{},{}",
                    v[0], v[1], v[2]
                )
                .unwrap();
            }
            s.push_str("\t\t}\n\t}\n");
            let parent = n.parent.map_or(0, |p| 1000 + p as i64);
            writeln!(conns, "\tC: \"OO\",{id},{parent}").unwrap();
            if let Some(g) = &n.mesh {
                let gid = 2000 + i as i64;
                writeln!(
                    s,
                    "\tGeometry: {gid}, \"Geometry::{}\", \"Mesh\" {{",
                    n.name
                )
                .unwrap();
                let (c, a) = list(g.vertices.iter().flatten());
                writeln!(s, "\t\tVertices: *{c} {{\n\t\t\ta: {a}\n\t\t}}").unwrap();
                let idx = g.polygons.iter().flat_map(|p| {
                    let last = p.len() - 1;
                    p.iter()
                        .enumerate()
                        .map(move |(k, &v)| if k == last { -(v as i64) - 1 } else { v as i64 })
                });
                let (c, a) = list(idx);
                writeln!(s, "\t\tPolygonVertexIndex: *{c} {{\n\t\t\ta: {a}\n\t\t}}").unwrap();
                s.push_str("\t\tGeometryVersion: 124\n");
                let mut layer = String::new();
                if let Some(nrm) = &g.normals {
                    let (c, a) = list(nrm.iter().flatten());
                    writeln!(s, "\t\tLayerElementNormal: 0 {{\n\t\t\tVersion: 101\n\t\t\tName: \"\"\n\t\t\tMappingInformationType: \"ByPolygonVertex\"\n\t\t\tReferenceInformationType: \"Direct\"\n\t\t\tNormals: *{c} {{\n\t\t\t\ta: {a}\n\t\t\t}}\n\t\t}}").unwrap();
                    layer.push_str("\t\t\tLayerElement:  {\n\t\t\t\tType: \"LayerElementNormal\"\n\t\t\t\tTypedIndex: 0\n\t\t\t}\n");
                }
                if let Some(pm) = &g.poly_materials {
                    let (c, a) = list(pm);
                    writeln!(s, "\t\tLayerElementMaterial: 0 {{\n\t\t\tVersion: 101\n\t\t\tName: \"\"\n\t\t\tMappingInformationType: \"ByPolygon\"\n\t\t\tReferenceInformationType: \"IndexToDirect\"\n\t\t\tMaterials: *{c} {{\n\t\t\t\ta: {a}\n\t\t\t}}\n\t\t}}").unwrap();
                    layer.push_str("\t\t\tLayerElement:  {\n\t\t\t\tType: \"LayerElementMaterial\"\n\t\t\t\tTypedIndex: 0\n\t\t\t}\n");
                }
                if !layer.is_empty() {
                    writeln!(s, "\t\tLayer: 0 {{\n\t\t\tVersion: 100\n{layer}\t\t}}").unwrap();
                }
                s.push_str("\t}\n");
                writeln!(conns, "\tC: \"OO\",{gid},{id}").unwrap();
            }
            for &m in &n.materials {
                writeln!(conns, "\tC: \"OO\",{},{id}", 3000 + m as i64).unwrap();
            }
        }
        for (i, (name, c)) in self.materials.iter().enumerate() {
            writeln!(s, "\tMaterial: {}, \"Material::{name}\", \"\" {{\n\t\tVersion: 102\n\t\tShadingModel: \"phong\"\n\t\tMultiLayer: 0\n\t\tProperties70:  {{\n\t\t\tP: \"DiffuseColor\", \"Color\", \"\", \"A\",{},{},{}\n\t\t}}\n\t}}", 3000 + i, c[0], c[1], c[2]).unwrap();
        }
        for (k, sk) in self.skins.iter().enumerate() {
            let sid = 4000 + 100 * k as i64;
            writeln!(s, "\tDeformer: {sid}, \"Deformer::Skin\", \"Skin\" {{\n\t\tVersion: 101\n\t\tLink_DeformAcuracy: 50\n\t}}").unwrap();
            writeln!(conns, "\tC: \"OO\",{sid},{}", 2000 + sk.mesh as i64).unwrap();
            for (j, c) in sk.clusters.iter().enumerate() {
                let cid = sid + 1 + j as i64;
                let (ni, ix) = list(c.weights.iter().map(|w| w.0));
                let (_, ws) = list(c.weights.iter().map(|w| w.1));
                let (_, link) = list(c.link);
                let (_, transform) = list(c.transform);
                writeln!(s, "\tDeformer: {cid}, \"SubDeformer::Cluster {j}\", \"Cluster\" {{\n\t\tVersion: 100\n\t\tUserData: \"\", \"\"\n\t\tIndexes: *{ni} {{\n\t\t\ta: {ix}\n\t\t}}\n\t\tWeights: *{ni} {{\n\t\t\ta: {ws}\n\t\t}}\n\t\tTransform: *16 {{\n\t\t\ta: {transform}\n\t\t}}\n\t\tTransformLink: *16 {{\n\t\t\ta: {link}\n\t\t}}\n\t}}").unwrap();
                writeln!(conns, "\tC: \"OO\",{cid},{sid}").unwrap();
                writeln!(conns, "\tC: \"OO\",{},{cid}", 1000 + c.bone as i64).unwrap();
            }
        }
        for (k, &mesh) in self.blend_shapes.iter().enumerate() {
            let id = 5000 + 10 * k as i64;
            writeln!(s, "\tGeometry: {id}, \"Geometry::Key{k}\", \"Shape\" {{\n\t\tVersion: 100\n\t\tIndexes: *1 {{\n\t\t\ta: 0\n\t\t}}\n\t\tVertices: *3 {{\n\t\t\ta: 0,0,1\n\t\t}}\n\t\tNormals: *3 {{\n\t\t\ta: 0,0,0\n\t\t}}\n\t}}").unwrap();
            writeln!(
                s,
                "\tDeformer: {}, \"Deformer::Morph{k}\", \"BlendShape\" {{\n\t\tVersion: 100\n\t}}",
                id + 1
            )
            .unwrap();
            writeln!(s, "\tDeformer: {}, \"SubDeformer::Key{k}\", \"BlendShapeChannel\" {{\n\t\tVersion: 100\n\t\tDeformPercent: 0\n\t\tFullWeights: *1 {{\n\t\t\ta: 100\n\t\t}}\n\t}}", id + 2).unwrap();
            writeln!(conns, "\tC: \"OO\",{},{}", id + 1, 2000 + mesh as i64).unwrap();
            writeln!(conns, "\tC: \"OO\",{},{}", id + 2, id + 1).unwrap();
            writeln!(conns, "\tC: \"OO\",{id},{}", id + 2).unwrap();
        }
        s.push_str("}\nConnections:  {\n");
        s.push_str(&conns);
        s.push_str("}\n");
        s
    }

    /// Write the file as `<dir>/<stem>.fbx` and return its path.
    pub fn write(&self, dir: &std::path::Path, stem: &str) -> std::path::PathBuf {
        let p = dir.join(format!("{stem}.fbx"));
        std::fs::write(&p, self.text()).unwrap();
        p
    }
}
