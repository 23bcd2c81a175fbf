//! Binary FBX 7.4 files, the subset Unity's importer and ufbx need for static meshes: a
//! Y-up, metre-unit file (`UnitScaleFactor` 100) whose root holds one Model per part,
//! each with its Mesh geometry (polygons of any size, per-vertex normals) and the file's
//! one material.
//!
//! The layout: a 27-byte header (`Kaydara FBX Binary  \0`, 0x1A 0x00, u32 version), then
//! node records — u32 offset of the record's end, u32 property count, u32 byte length of
//! the property list, u8 name length, the name, the properties, the nested records and,
//! when there are any, a 13-byte null record — and a null record and footer at the end.
//! Array properties are written raw (encoding 0) or, as exporters do, zlib-compressed
//! (encoding 1).

use glam::Vec3;

/// FBX 7.4: offsets and counts are 32-bit.
const VERSION: u32 = 7400;

/// One mesh object of a file: a Model node directly under the root with its geometry.
#[derive(Clone, Debug, Default)]
pub struct Part {
    pub name: String,
    /// Local translation of the Model (metres, the file's right-handed Y-up frame).
    pub translation: Vec3,
    pub positions: Vec<Vec3>,
    /// One unit normal per position.
    pub normals: Vec<Vec3>,
    /// Polygons as position indices, counter-clockwise seen from outside.
    pub polygons: Vec<Vec<u32>>,
}

impl Part {
    /// Triangles Unity makes of it (a polygon of n corners gives n − 2).
    pub fn triangle_count(&self) -> usize {
        self.polygons
            .iter()
            .map(|p| p.len().saturating_sub(2))
            .sum()
    }
}

/// A whole file: its parts and its material (name, linear diffuse colour).
pub struct File<'a> {
    pub parts: &'a [Part],
    pub material: &'a str,
    pub color: [f32; 3],
    /// Deflate the arrays (what the FBX SDK writes), so a reader inflates them.
    pub compress: bool,
}

enum Prop {
    I32(i32),
    I64(i64),
    F64(f64),
    Str(Vec<u8>),
    F64s(Vec<f64>),
    I32s(Vec<i32>),
}

struct Node {
    name: &'static str,
    props: Vec<Prop>,
    children: Vec<Node>,
}

fn node(name: &'static str, props: Vec<Prop>, children: Vec<Node>) -> Node {
    Node {
        name,
        props,
        children,
    }
}

fn s(text: &str) -> Prop {
    Prop::Str(text.as_bytes().to_vec())
}

/// An object's name and class as FBX 7 stores them: `name\0\x01Class`.
fn object_name(name: &str, class: &str) -> Prop {
    let mut b = name.as_bytes().to_vec();
    b.extend_from_slice(b"\x00\x01");
    b.extend_from_slice(class.as_bytes());
    Prop::Str(b)
}

/// A `Properties70` entry: `P: name, type, label, flags, values…`.
fn p(name: &str, ty: &str, label: &str, flags: &str, values: Vec<Prop>) -> Node {
    let mut props = vec![s(name), s(ty), s(label), s(flags)];
    props.extend(values);
    node("P", props, vec![])
}

fn p_int(name: &str, v: i32) -> Node {
    p(name, "int", "Integer", "", vec![Prop::I32(v)])
}

/// An animatable vector property ("A" flag), as the SDK writes transforms and colours.
fn p_vec(name: &str, ty: &str, v: [f64; 3]) -> Node {
    p(name, ty, "", "A", v.map(Prop::F64).into())
}

fn write_prop(out: &mut Vec<u8>, prop: &Prop, compress: bool) {
    match prop {
        Prop::I32(v) => {
            out.push(b'I');
            out.extend_from_slice(&v.to_le_bytes());
        }
        Prop::I64(v) => {
            out.push(b'L');
            out.extend_from_slice(&v.to_le_bytes());
        }
        Prop::F64(v) => {
            out.push(b'D');
            out.extend_from_slice(&v.to_le_bytes());
        }
        Prop::Str(b) => {
            out.push(b'S');
            out.extend_from_slice(&(b.len() as u32).to_le_bytes());
            out.extend_from_slice(b);
        }
        Prop::F64s(v) => {
            let raw: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
            array(out, b'd', v.len(), &raw, compress);
        }
        Prop::I32s(v) => {
            let raw: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
            array(out, b'i', v.len(), &raw, compress);
        }
    }
}

/// Type code, u32 element count, u32 encoding (0 raw, 1 zlib), u32 byte length, data.
fn array(out: &mut Vec<u8>, code: u8, len: usize, raw: &[u8], compress: bool) {
    let zipped;
    let (encoding, data) = if compress {
        zipped = miniz_oxide::deflate::compress_to_vec_zlib(raw, 6);
        (1u32, zipped.as_slice())
    } else {
        (0u32, raw)
    };
    out.push(code);
    out.extend_from_slice(&(len as u32).to_le_bytes());
    out.extend_from_slice(&encoding.to_le_bytes());
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
}

const NULL_RECORD: [u8; 13] = [0; 13];

fn write_node(out: &mut Vec<u8>, n: &Node, compress: bool) {
    let start = out.len();
    out.extend_from_slice(&[0; 12]);
    out.push(n.name.len() as u8);
    out.extend_from_slice(n.name.as_bytes());
    let props_start = out.len();
    for prop in &n.props {
        write_prop(out, prop, compress);
    }
    let props_len = (out.len() - props_start) as u32;
    for c in &n.children {
        write_node(out, c, compress);
    }
    // The SDK ends a nested list with a null record, and marks an empty node with one.
    if !n.children.is_empty() || n.props.is_empty() {
        out.extend_from_slice(&NULL_RECORD);
    }
    let end = out.len() as u32;
    out[start..start + 4].copy_from_slice(&end.to_le_bytes());
    out[start + 4..start + 8].copy_from_slice(&(n.props.len() as u32).to_le_bytes());
    out[start + 8..start + 12].copy_from_slice(&props_len.to_le_bytes());
}

fn geometry(id: i64, part: &Part) -> Node {
    let flat =
        |v: &[Vec3]| Prop::F64s(v.iter().flat_map(|p| p.to_array().map(f64::from)).collect());
    // The last corner of each polygon is stored as −(index + 1).
    let mut indices = Vec::with_capacity(part.polygons.iter().map(Vec::len).sum());
    for poly in &part.polygons {
        if let Some((&last, rest)) = poly.split_last() {
            indices.extend(rest.iter().map(|&i| i as i32));
            indices.push(-(last as i32) - 1);
        }
    }
    let layer_element = |ty: &str| {
        node(
            "LayerElement",
            vec![],
            vec![
                node("Type", vec![s(ty)], vec![]),
                node("TypedIndex", vec![Prop::I32(0)], vec![]),
            ],
        )
    };
    node(
        "Geometry",
        vec![
            Prop::I64(id),
            object_name(&part.name, "Geometry"),
            s("Mesh"),
        ],
        vec![
            node("GeometryVersion", vec![Prop::I32(124)], vec![]),
            node("Vertices", vec![flat(&part.positions)], vec![]),
            node("PolygonVertexIndex", vec![Prop::I32s(indices)], vec![]),
            node(
                "LayerElementNormal",
                vec![Prop::I32(0)],
                vec![
                    node("Version", vec![Prop::I32(101)], vec![]),
                    node("Name", vec![s("")], vec![]),
                    node("MappingInformationType", vec![s("ByVertice")], vec![]),
                    node("ReferenceInformationType", vec![s("Direct")], vec![]),
                    node("Normals", vec![flat(&part.normals)], vec![]),
                ],
            ),
            node(
                "LayerElementMaterial",
                vec![Prop::I32(0)],
                vec![
                    node("Version", vec![Prop::I32(101)], vec![]),
                    node("Name", vec![s("")], vec![]),
                    node("MappingInformationType", vec![s("AllSame")], vec![]),
                    node("ReferenceInformationType", vec![s("IndexToDirect")], vec![]),
                    node("Materials", vec![Prop::I32s(vec![0])], vec![]),
                ],
            ),
            node(
                "Layer",
                vec![Prop::I32(0)],
                vec![
                    node("Version", vec![Prop::I32(100)], vec![]),
                    layer_element("LayerElementNormal"),
                    layer_element("LayerElementMaterial"),
                ],
            ),
        ],
    )
}

fn model(id: i64, part: &Part) -> Node {
    let t = part.translation.to_array().map(f64::from);
    node(
        "Model",
        vec![Prop::I64(id), object_name(&part.name, "Model"), s("Mesh")],
        vec![
            node("Version", vec![Prop::I32(232)], vec![]),
            node(
                "Properties70",
                vec![],
                vec![
                    p_vec("Lcl Translation", "Lcl Translation", t),
                    p_vec("Lcl Rotation", "Lcl Rotation", [0.0; 3]),
                    p_vec("Lcl Scaling", "Lcl Scaling", [1.0; 3]),
                ],
            ),
        ],
    )
}

fn material(id: i64, name: &str, color: [f32; 3]) -> Node {
    node(
        "Material",
        vec![Prop::I64(id), object_name(name, "Material"), s("")],
        vec![
            node("Version", vec![Prop::I32(102)], vec![]),
            node("ShadingModel", vec![s("lambert")], vec![]),
            node("MultiLayer", vec![Prop::I32(0)], vec![]),
            node(
                "Properties70",
                vec![],
                vec![p_vec("DiffuseColor", "Color", color.map(f64::from))],
            ),
        ],
    )
}

fn connect(child: i64, parent: i64) -> Node {
    node(
        "C",
        vec![s("OO"), Prop::I64(child), Prop::I64(parent)],
        vec![],
    )
}

/// The file's bytes.
pub fn write(file: &File) -> Vec<u8> {
    // Object ids only need to be unique and non-zero (0 is the root).
    let (material_id, first) = (1_000, 10_000);
    let mut objects = Vec::new();
    let mut connections = Vec::new();
    for (k, part) in file.parts.iter().enumerate() {
        let (m, g) = (first + 2 * k as i64, first + 2 * k as i64 + 1);
        objects.push(geometry(g, part));
        objects.push(model(m, part));
        connections.push(connect(m, 0));
        connections.push(connect(g, m));
        connections.push(connect(material_id, m));
    }
    objects.push(material(material_id, file.material, file.color));
    let object_type = |ty: &str, count: usize| {
        node(
            "ObjectType",
            vec![s(ty)],
            vec![node("Count", vec![Prop::I32(count as i32)], vec![])],
        )
    };
    let n = file.parts.len();
    let top = [
        node(
            "FBXHeaderExtension",
            vec![],
            vec![
                node("FBXHeaderVersion", vec![Prop::I32(1003)], vec![]),
                node("FBXVersion", vec![Prop::I32(VERSION as i32)], vec![]),
                node("Creator", vec![s("unitrace scenegen")], vec![]),
            ],
        ),
        node(
            "GlobalSettings",
            vec![],
            vec![
                node("Version", vec![Prop::I32(1000)], vec![]),
                node(
                    "Properties70",
                    vec![],
                    vec![
                        p_int("UpAxis", 1),
                        p_int("UpAxisSign", 1),
                        p_int("FrontAxis", 2),
                        p_int("FrontAxisSign", 1),
                        p_int("CoordAxis", 0),
                        p_int("CoordAxisSign", 1),
                        // Centimetres per unit: the file is in metres.
                        p(
                            "UnitScaleFactor",
                            "double",
                            "Number",
                            "",
                            vec![Prop::F64(100.0)],
                        ),
                        p(
                            "OriginalUnitScaleFactor",
                            "double",
                            "Number",
                            "",
                            vec![Prop::F64(100.0)],
                        ),
                    ],
                ),
            ],
        ),
        node(
            "Definitions",
            vec![],
            vec![
                node("Version", vec![Prop::I32(100)], vec![]),
                node("Count", vec![Prop::I32(1 + 2 * n as i32 + 1)], vec![]),
                object_type("GlobalSettings", 1),
                object_type("Model", n),
                object_type("Geometry", n),
                object_type("Material", 1),
            ],
        ),
        node("Objects", vec![], objects),
        node("Connections", vec![], connections),
    ];
    let mut out = Vec::new();
    out.extend_from_slice(b"Kaydara FBX Binary  \0\x1a\x00");
    out.extend_from_slice(&VERSION.to_le_bytes());
    for n in &top {
        write_node(&mut out, n, file.compress);
    }
    out.extend_from_slice(&NULL_RECORD);
    footer(&mut out);
    out
}

/// What the SDK writes after the last record: a footer id, padding to 16 bytes, the
/// version, 120 zero bytes and a fixed 16-byte magic.
fn footer(out: &mut Vec<u8>) {
    out.extend_from_slice(&[
        0xfa, 0xbc, 0xab, 0x09, 0xd0, 0xc8, 0xd4, 0x66, 0xb1, 0x76, 0xfb, 0x83, 0x1c, 0xf7, 0x26,
        0x7e,
    ]);
    out.extend_from_slice(&[0; 4]);
    let pad = (16 - out.len() % 16) % 16;
    out.extend(std::iter::repeat_n(0u8, pad));
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&[0; 120]);
    out.extend_from_slice(&[
        0xf8, 0x5a, 0x8c, 0x6a, 0xde, 0xf5, 0xd9, 0x7e, 0xec, 0xe9, 0x0c, 0xe3, 0x75, 0x8f, 0x29,
        0x0b,
    ]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(name: &str, translation: Vec3, polygons: Vec<Vec<u32>>) -> Part {
        Part {
            name: name.into(),
            translation,
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(0.0, 0.0, -1.0),
            ],
            normals: vec![Vec3::Y; 4],
            polygons,
        }
    }

    #[test]
    fn ufbx_reads_back_what_is_written() {
        read_back(false);
    }

    #[test]
    fn ufbx_reads_back_what_is_written_compressed() {
        read_back(true);
    }

    fn read_back(compress: bool) {
        let parts = [
            square("Quad", Vec3::new(1.0, 2.0, 3.0), vec![vec![0, 1, 2, 3]]),
            square(
                "Tris",
                Vec3::new(-4.0, 0.0, 0.5),
                vec![vec![0, 1, 2], vec![0, 2, 3]],
            ),
        ];
        let bytes = write(&File {
            parts: &parts,
            material: "Paint",
            color: [0.25, 0.5, 0.75],
            compress,
        });
        assert!(bytes.starts_with(b"Kaydara FBX Binary  \0\x1a\x00"));
        assert_eq!(bytes[23..27], 7400u32.to_le_bytes());
        let opts = ufbx::LoadOpts {
            strict: true,
            file_format: ufbx::FileFormat::Fbx,
            ..Default::default()
        };
        let scene = ufbx::load_memory(&bytes, opts).unwrap_or_else(|e| panic!("{}", e.description));
        assert_eq!(scene.metadata.version, 7400);
        assert!(!scene.metadata.ascii);
        assert_eq!(scene.settings.unit_meters, 1.0);
        assert_eq!(scene.settings.axes.up, ufbx::CoordinateAxis::PositiveY);
        assert_eq!(scene.settings.axes.front, ufbx::CoordinateAxis::PositiveZ);
        assert_eq!(scene.settings.axes.right, ufbx::CoordinateAxis::PositiveX);
        let root = &scene.root_node;
        assert_eq!(root.children.len(), 2);
        for (node, part) in root.children.iter().zip(&parts) {
            assert_eq!(node.element.name.to_string(), part.name);
            let t = node.local_transform.translation;
            assert_eq!([t.x, t.y, t.z], part.translation.to_array().map(f64::from));
            let mesh = node.mesh.as_ref().expect("a mesh");
            assert_eq!(mesh.num_triangles, 2);
            assert_eq!(mesh.faces.len(), part.polygons.len());
            let corners: Vec<u32> = mesh.vertex_indices.iter().copied().collect();
            assert_eq!(corners, part.polygons.concat());
            let pos: Vec<[f64; 3]> = mesh.vertices.iter().map(|v| [v.x, v.y, v.z]).collect();
            let want: Vec<[f64; 3]> = part
                .positions
                .iter()
                .map(|p| p.to_array().map(f64::from))
                .collect();
            assert_eq!(pos, want);
            assert!(mesh.vertex_normal.exists);
            for i in 0..mesh.num_indices {
                let n = mesh.vertex_normal[i];
                assert_eq!([n.x, n.y, n.z], [0.0, 1.0, 0.0]);
            }
            assert_eq!(node.materials.len(), 1);
            assert_eq!(node.materials[0].element.name.to_string(), "Paint");
            let c = node.materials[0].fbx.diffuse_color.value_vec4;
            assert_eq!([c.x, c.y, c.z], [0.25, 0.5, 0.75]);
        }
    }
}
