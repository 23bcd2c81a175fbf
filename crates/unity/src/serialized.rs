//! Unity's binary serialized files ("SerializedFile"): the format of built player data and
//! of the assets Unity writes in binary even in a Force Text project (`TerrainData`
//! `.asset` files). An editor file embeds the type tree of every class it holds, so an
//! object's fields are read by walking that tree, with no per-class code here.
//!
//! Every length and count read from the file is checked against the bytes left before
//! anything is allocated, reading an object never leaves the object's own bytes, and the
//! type tree walk has a depth limit: a damaged or hostile file is an error, never a panic
//! or an unbounded allocation.

/// Oldest format version read (Unity 3.5's); Unity 5.0 writes 14, 2022 and 6 write 22.
const MIN_VERSION: u32 = 9;
/// Newest format version whose layout is known (Unity 2022 and Unity 6 write 22). A later
/// version may move fields, and misreading it would only produce confusing errors.
const MAX_VERSION: u32 = 22;
/// Deepest type tree nesting read; Unity's classes nest a dozen levels at most.
const MAX_DEPTH: usize = 64;
/// `metaFlag` bit: align the stream to 4 bytes after this node.
const ALIGN_BYTES: u32 = 0x4000;
/// Top bit of a type tree string offset: the offset is into [`COMMON_STRINGS`].
const COMMON_BIT: u32 = 0x8000_0000;

/// Unity's built-in table of type tree strings, which a tree names by byte offset into
/// this concatenation. Order matters: the offsets are fixed.
const COMMON_STRINGS: &str = "AABB\0AnimationClip\0AnimationCurve\0AnimationState\0Array\0\
Base\0BitField\0bitset\0bool\0char\0ColorRGBA\0Component\0data\0deque\0double\0\
dynamic_array\0FastPropertyName\0first\0float\0Font\0GameObject\0Generic Mono\0\
GradientNEW\0GUID\0GUIStyle\0int\0list\0long long\0map\0Matrix4x4f\0MdFour\0\
MonoBehaviour\0MonoScript\0m_ByteSize\0m_Curve\0m_EditorClassIdentifier\0\
m_EditorHideFlags\0m_Enabled\0m_ExtensionPtr\0m_GameObject\0m_Index\0m_IsArray\0\
m_IsStatic\0m_MetaFlag\0m_Name\0m_ObjectHideFlags\0m_PrefabInternal\0\
m_PrefabParentObject\0m_Script\0m_StaticEditorFlags\0m_Type\0m_Version\0Object\0pair\0\
PPtr<Component>\0PPtr<GameObject>\0PPtr<Material>\0PPtr<MonoBehaviour>\0\
PPtr<MonoScript>\0PPtr<Object>\0PPtr<Prefab>\0PPtr<Sprite>\0PPtr<TextAsset>\0\
PPtr<Texture>\0PPtr<Texture2D>\0PPtr<Transform>\0Prefab\0Quaternionf\0Rectf\0RectInt\0\
RectOffset\0second\0set\0short\0size\0SInt16\0SInt32\0SInt64\0SInt8\0staticvector\0\
string\0TextAsset\0TextMesh\0Texture\0Texture2D\0Transform\0TypelessData\0UInt16\0\
UInt32\0UInt64\0UInt8\0unsigned int\0unsigned long long\0unsigned short\0vector\0\
Vector2f\0Vector3f\0Vector4f\0m_ScriptingClassIdentifier\0Gradient\0Type*\0\
int2_storage\0int3_storage\0BoundsInt\0m_CorrespondingSourceObject\0m_PrefabInstance\0\
m_PrefabAsset\0FileSize\0Hash128\0RenderingLayerMask\0";

/// The common string starting at byte `offset` of [`COMMON_STRINGS`]; `None` when the
/// offset is not the start of one of its strings.
fn common_string(offset: u32) -> Option<&'static str> {
    let table = COMMON_STRINGS.as_bytes();
    let at = usize::try_from(offset).ok()?;
    if at >= table.len() || (at > 0 && table[at - 1] != 0) {
        return None;
    }
    let len = table[at..].iter().position(|&b| b == 0)?;
    COMMON_STRINGS.get(at..at + len)
}

#[derive(Debug, thiserror::Error)]
pub enum SerializedError {
    #[error("{path}: byte {offset}: {message}")]
    Malformed {
        path: String,
        offset: u64,
        message: String,
    },
    #[error("{path}: byte 8: serialized format version {version} is older than Unity 5")]
    TooOld { path: String, version: u32 },
    #[error(
        "{path}: byte 8: serialized format version {version} is newer than this reader \
         knows (up to {MAX_VERSION})"
    )]
    TooNew { path: String, version: u32 },
    #[error("{path}: no object with path ID {path_id}")]
    NoObject { path: String, path_id: i64 },
    #[error(
        "{path}: byte {offset}: object {path_id}: the file has no type tree (built player \
         data), so its fields cannot be read"
    )]
    NoTypeTree {
        path: String,
        offset: u64,
        path_id: i64,
    },
}

type Result<T> = std::result::Result<T, SerializedError>;

/// A field's value, as the type tree describes it.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Bool(bool),
    /// Every integer type; a `UInt64` above `i64::MAX` wraps to a negative value.
    Int(i64),
    Float(f64),
    /// A `string` field, UTF-8 decoded lossily.
    Str(String),
    /// `TypelessData`, and arrays of `UInt8`, `SInt8` or `char`.
    Bytes(Vec<u8>),
    /// Arrays of any other numeric primitive, one entry per element (read in bulk: a
    /// heightmap holds up to 4097² `SInt16`).
    Numbers(Vec<f64>),
    /// Other arrays; a `map`'s entries are `Map`s of `first` and `second`.
    Seq(Vec<Value>),
    /// A compound node: its children by field name, in file order.
    Map(Vec<(String, Value)>),
}

impl Value {
    /// First field named `key` (compounds only).
    pub fn get(&self, key: &str) -> Option<&Value> {
        match self {
            Value::Map(kv) => kv.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// Follow a path of field names.
    pub fn path(&self, keys: &[&str]) -> Option<&Value> {
        keys.iter().try_fold(self, |v, k| v.get(k))
    }

    /// An `Int`, a `Bool` as 0 or 1, or a `Float` holding a whole number in range (Unity
    /// stores some counts as floats).
    pub fn as_i64(&self) -> Option<i64> {
        match *self {
            Value::Int(i) => Some(i),
            Value::Bool(b) => Some(i64::from(b)),
            Value::Float(f) if f.fract() == 0.0 && f.abs() < 9.2e18 => Some(f as i64),
            _ => None,
        }
    }

    /// A `Float` or an `Int`.
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Value::Float(f) => Some(f),
            Value::Int(i) => Some(i as f64),
            _ => None,
        }
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::Str(s) => Some(s),
            _ => None,
        }
    }
}

/// An object listed in the file.
#[derive(Debug, Clone)]
pub struct ObjectInfo {
    pub path_id: i64,
    pub class_id: i32,
    /// Absolute file offset of the object's data (`u64::MAX` when the header's offsets
    /// overflow; reading then fails).
    byte_start: u64,
    byte_size: u32,
    /// Index into the file's types; `None` when an old file names a class it has no type for.
    type_index: Option<usize>,
}

/// Another file this one's PPtrs point into: `m_FileID` n ≥ 1 is `externals[n - 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct External {
    /// 32 lowercase hex digits, as in `.meta` files.
    pub guid: String,
    pub path: String,
}

/// A parsed serialized file: its object table and type trees; object fields are read on
/// demand with [`SerializedFile::read`].
pub struct SerializedFile {
    pub version: u32,
    pub unity_version: String,
    pub objects: Vec<ObjectInfo>,
    pub externals: Vec<External>,
    bytes: Vec<u8>,
    types: Vec<SerializedType>,
    has_type_trees: bool,
    big_endian: bool,
    path: String,
}

impl std::fmt::Debug for SerializedFile {
    // Not derived: the file's bytes would flood any message that prints it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SerializedFile")
            .field("path", &self.path)
            .field("version", &self.version)
            .field("unity_version", &self.unity_version)
            .field("objects", &self.objects.len())
            .field("externals", &self.externals)
            .finish()
    }
}

struct SerializedType {
    class_id: i32,
    tree: TypeTree,
}

/// One type tree node, as Unity lists them (depth first).
#[derive(Debug)]
struct TypeNode {
    type_name: String,
    name: String,
    level: u8,
    /// Bit 0: this is an `Array` node.
    type_flags: u32,
    byte_size: i32,
    meta_flag: u32,
}

/// How a node's value is read, decided once per tree.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Prim(Prim),
    Str,
    Typeless,
    /// An array; the index is its `Array` node (the node itself or its first child).
    Array(usize),
    Compound,
    /// A leaf of a type this reader does not know and cannot size.
    Unreadable,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Prim {
    Bool,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Prim {
    fn from_name(name: &str) -> Option<Prim> {
        Some(match name {
            "bool" => Prim::Bool,
            "SInt8" => Prim::I8,
            "UInt8" | "char" => Prim::U8,
            "SInt16" | "short" => Prim::I16,
            "UInt16" | "unsigned short" => Prim::U16,
            "SInt32" | "int" => Prim::I32,
            "UInt32" | "unsigned int" | "Type*" => Prim::U32,
            "SInt64" | "long long" => Prim::I64,
            "UInt64" | "unsigned long long" | "FileSize" => Prim::U64,
            "float" => Prim::F32,
            "double" => Prim::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Prim::Bool | Prim::I8 | Prim::U8 => 1,
            Prim::I16 | Prim::U16 => 2,
            Prim::I32 | Prim::U32 | Prim::F32 => 4,
            Prim::I64 | Prim::U64 | Prim::F64 => 8,
        }
    }

    /// An element as a number (for bulk arrays); `b` is exactly [`Prim::size`] bytes.
    fn number(self, b: &[u8], big: bool) -> f64 {
        macro_rules! num {
            ($t:ty) => {{
                let mut a = [0u8; std::mem::size_of::<$t>()];
                a.copy_from_slice(b);
                if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }
            }};
        }
        match self {
            Prim::Bool | Prim::U8 => f64::from(b[0]),
            Prim::I8 => f64::from(b[0] as i8),
            Prim::I16 => f64::from(num!(i16)),
            Prim::U16 => f64::from(num!(u16)),
            Prim::I32 => f64::from(num!(i32)),
            Prim::U32 => f64::from(num!(u32)),
            Prim::I64 => num!(i64) as f64,
            Prim::U64 => num!(u64) as f64,
            Prim::F32 => f64::from(num!(f32)),
            Prim::F64 => num!(f64),
        }
    }
}

/// A type tree with each node's children, read kind and minimum serialized size
/// precomputed (the size bounds array counts before anything is allocated).
#[derive(Debug, Default)]
struct TypeTree {
    nodes: Vec<TypeNode>,
    children: Vec<Vec<usize>>,
    kinds: Vec<Kind>,
    min_size: Vec<u64>,
}

impl TypeTree {
    /// Links the depth-first node list into a tree; `err` reports a malformed one.
    fn new(nodes: Vec<TypeNode>, err: impl Fn(String) -> SerializedError) -> Result<TypeTree> {
        let n = nodes.len();
        let mut children = vec![Vec::new(); n];
        let mut stack: Vec<usize> = Vec::new();
        for (i, node) in nodes.iter().enumerate() {
            while stack.last().is_some_and(|&p| nodes[p].level >= node.level) {
                stack.pop();
            }
            match stack.last() {
                Some(&p) if u16::from(nodes[p].level) + 1 == u16::from(node.level) => {
                    children[p].push(i)
                }
                None if i == 0 => {}
                _ => {
                    return Err(err(format!(
                        "type tree node {i} ({}) at level {} has no parent one level up",
                        node.name, node.level
                    )))
                }
            }
            stack.push(i);
        }
        let is_array_node =
            |i: usize| nodes[i].type_flags & 1 != 0 || nodes[i].type_name == "Array";
        let kinds: Vec<Kind> = (0..n)
            .map(|i| {
                let node = &nodes[i];
                let leaf = children[i].is_empty();
                match node.type_name.as_str() {
                    "string" => Kind::Str,
                    "TypelessData" => Kind::Typeless,
                    _ if is_array_node(i) => Kind::Array(i),
                    _ if children[i].first().is_some_and(|&c| is_array_node(c)) => {
                        Kind::Array(children[i][0])
                    }
                    t => match Prim::from_name(t) {
                        Some(p) => Kind::Prim(p),
                        // A leaf of an unknown type still has a size to read it by.
                        None if leaf => match node.byte_size {
                            1 => Kind::Prim(Prim::U8),
                            2 => Kind::Prim(Prim::U16),
                            4 => Kind::Prim(Prim::U32),
                            8 => Kind::Prim(Prim::U64),
                            _ => Kind::Unreadable,
                        },
                        None => Kind::Compound,
                    },
                }
            })
            .collect();
        // Children follow their parent, so a reverse pass sees them first.
        let mut min_size = vec![0u64; n];
        for i in (0..n).rev() {
            min_size[i] = match kinds[i] {
                Kind::Prim(p) => p.size() as u64,
                Kind::Str | Kind::Typeless | Kind::Array(_) => 4,
                Kind::Compound => children[i]
                    .iter()
                    .fold(0u64, |s, &c| s.saturating_add(min_size[c])),
                Kind::Unreadable => 0,
            };
        }
        Ok(TypeTree {
            nodes,
            children,
            kinds,
            min_size,
        })
    }
}

/// A bounded little- or big-endian cursor over part of the file.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Reading stops here (≤ `bytes.len()`).
    end: usize,
    /// Alignment is relative to this offset: the file start, or the object's start.
    base: usize,
    big: bool,
    path: &'a str,
    /// Values still allowed for this object: a tree of empty compounds reads no bytes, so
    /// the byte bound alone would not bound the values built from a hostile file.
    budget: u64,
}

macro_rules! read_num {
    ($name:ident, $t:ty) => {
        fn $name(&mut self, what: &str) -> Result<$t> {
            let a = self.array::<{ std::mem::size_of::<$t>() }>(what)?;
            Ok(if self.big {
                <$t>::from_be_bytes(a)
            } else {
                <$t>::from_le_bytes(a)
            })
        }
    };
}

impl<'a> Reader<'a> {
    fn err(&self, message: impl Into<String>) -> SerializedError {
        SerializedError::Malformed {
            path: self.path.to_string(),
            offset: self.pos as u64,
            message: message.into(),
        }
    }

    fn left(&self) -> usize {
        self.end.saturating_sub(self.pos)
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        if n > self.left() {
            return Err(self.err(format!("{what}: needs {n} bytes, {} left", self.left())));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        Ok(a)
    }

    fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.array::<1>(what)?[0])
    }

    read_num!(u16, u16);
    read_num!(i16, i16);
    read_num!(u32, u32);
    read_num!(i32, i32);
    read_num!(u64, u64);
    read_num!(i64, i64);
    read_num!(f32, f32);
    read_num!(f64, f64);

    /// A count or length: non-negative, and `count × min_size` must fit in what is left.
    fn count(&mut self, min_size: u64, what: &str) -> Result<usize> {
        let at = self.pos;
        let n = self.i32(what)?;
        let fits = u64::try_from(n)
            .ok()
            .filter(|&n| n.saturating_mul(min_size.max(1)) <= self.left() as u64);
        match fits {
            Some(n) => Ok(n as usize),
            None => {
                self.pos = at;
                Err(self.err(format!(
                    "{what} {n} does not fit in the {} bytes left",
                    self.left().saturating_sub(4)
                )))
            }
        }
    }

    /// A NUL-terminated string (lossy UTF-8).
    fn cstr(&mut self, what: &str) -> Result<String> {
        let rest = &self.bytes[self.pos..self.end];
        let Some(len) = rest.iter().position(|&b| b == 0) else {
            return Err(self.err(format!(
                "{what}: no terminating NUL before byte {}",
                self.end
            )));
        };
        let s = String::from_utf8_lossy(&rest[..len]).into_owned();
        self.pos += len + 1;
        Ok(s)
    }

    /// Skip to the next multiple of 4 from `base`. Padding cut off by the end is not an
    /// error: the next read, if any, reports the shortage.
    fn align4(&mut self) {
        let pad = (4 - (self.pos - self.base) % 4) % 4;
        self.pos = (self.pos + pad).min(self.end.max(self.pos));
    }

    fn spend(&mut self, values: u64) -> Result<()> {
        if values > self.budget {
            return Err(self.err("more values than the object's size allows"));
        }
        self.budget -= values;
        Ok(())
    }

    fn prim(&mut self, p: Prim, what: &str) -> Result<Value> {
        Ok(match p {
            Prim::Bool => Value::Bool(self.u8(what)? != 0),
            Prim::I8 => Value::Int(i64::from(self.u8(what)? as i8)),
            Prim::U8 => Value::Int(i64::from(self.u8(what)?)),
            Prim::I16 => Value::Int(i64::from(self.i16(what)?)),
            Prim::U16 => Value::Int(i64::from(self.u16(what)?)),
            Prim::I32 => Value::Int(i64::from(self.i32(what)?)),
            Prim::U32 => Value::Int(i64::from(self.u32(what)?)),
            Prim::I64 => Value::Int(self.i64(what)?),
            Prim::U64 => Value::Int(self.u64(what)? as i64),
            Prim::F32 => Value::Float(f64::from(self.f32(what)?)),
            Prim::F64 => Value::Float(self.f64(what)?),
        })
    }

    /// Node `i`'s value, then the alignment its `metaFlag` asks for.
    fn node(&mut self, tree: &TypeTree, i: usize, depth: usize) -> Result<Value> {
        let node = &tree.nodes[i];
        if depth > MAX_DEPTH {
            return Err(self.err(format!(
                "{}: type tree nested deeper than {MAX_DEPTH} levels",
                node.name
            )));
        }
        self.spend(1)?;
        let value = match tree.kinds[i] {
            Kind::Prim(p) => self.prim(p, &node.name)?,
            Kind::Str => {
                let len = self.count(1, &node.name)?;
                let s = String::from_utf8_lossy(self.take(len, &node.name)?).into_owned();
                // The string's own Array child carries the alignment flag.
                let array = tree.children[i].first().map(|&c| &tree.nodes[c]);
                if array.is_some_and(|a| a.meta_flag & ALIGN_BYTES != 0) {
                    self.align4();
                }
                Value::Str(s)
            }
            Kind::Typeless => {
                let len = self.count(1, &node.name)?;
                Value::Bytes(self.take(len, &node.name)?.to_vec())
            }
            Kind::Array(a) => self.array_value(tree, a, &node.name, depth)?,
            Kind::Compound => {
                let mut fields = Vec::with_capacity(tree.children[i].len());
                for &c in &tree.children[i] {
                    fields.push((tree.nodes[c].name.clone(), self.node(tree, c, depth + 1)?));
                }
                Value::Map(fields)
            }
            Kind::Unreadable => {
                return Err(self.err(format!(
                    "{}: type {} has no fields and an unreadable size {}",
                    node.name, node.type_name, node.byte_size
                )))
            }
        };
        if node.meta_flag & ALIGN_BYTES != 0 {
            self.align4();
        }
        Ok(value)
    }

    /// An array whose `Array` node is `a`: its children are the size and the element.
    fn array_value(
        &mut self,
        tree: &TypeTree,
        a: usize,
        name: &str,
        depth: usize,
    ) -> Result<Value> {
        let Some(&elem) = tree.children[a].get(1) else {
            return Err(self.err(format!("{name}: Array node without size and data children")));
        };
        let value = match tree.kinds[elem] {
            Kind::Prim(Prim::Bool) => {
                let n = self.count(1, name)?;
                self.spend(n as u64)?;
                let raw = self.take(n, name)?;
                Value::Seq(raw.iter().map(|&b| Value::Bool(b != 0)).collect())
            }
            Kind::Prim(Prim::U8 | Prim::I8) => {
                let n = self.count(1, name)?;
                Value::Bytes(self.take(n, name)?.to_vec())
            }
            Kind::Prim(p) => {
                let size = p.size();
                let n = self.count(size as u64, name)?;
                let raw = self.take(n * size, name)?;
                let big = self.big;
                Value::Numbers(raw.chunks_exact(size).map(|b| p.number(b, big)).collect())
            }
            _ => {
                let n = self.count(tree.min_size[elem], name)?;
                // Reserve only what the bytes left could hold even for empty elements.
                let mut items = Vec::with_capacity(n.min(self.left().max(1)));
                for _ in 0..n {
                    items.push(self.node(tree, elem, depth + 1)?);
                }
                Value::Seq(items)
            }
        };
        if tree.nodes[a].meta_flag & ALIGN_BYTES != 0 {
            self.align4();
        }
        Ok(value)
    }

    /// A type tree string: local buffer offset, or common table offset with the top bit.
    fn tree_string(&self, buf: &[u8], offset: u32) -> Result<String> {
        if offset & COMMON_BIT != 0 {
            return common_string(offset & !COMMON_BIT)
                .map(str::to_string)
                .ok_or_else(|| {
                    self.err(format!(
                        "type tree names common string offset {}, not in Unity's table",
                        offset & !COMMON_BIT
                    ))
                });
        }
        let rest = buf.get(offset as usize..).unwrap_or(&[]);
        match rest.iter().position(|&b| b == 0) {
            Some(len) => Ok(String::from_utf8_lossy(&rest[..len]).into_owned()),
            None => Err(self.err(format!(
                "type tree string offset {offset} is outside its {}-byte string buffer",
                buf.len()
            ))),
        }
    }

    /// A type tree in the blob layout (format 10 and 12+).
    fn blob_tree(&mut self, version: u32) -> Result<Vec<TypeNode>> {
        let node_size: u64 = if version >= 19 { 32 } else { 24 };
        let count = self.count(node_size, "type tree node count")?;
        let buf_len = self.i32("type tree string buffer size")?;
        let Some(buf_len) = usize::try_from(buf_len)
            .ok()
            .filter(|&b| (count as u64) * node_size + b as u64 <= self.left() as u64)
        else {
            return Err(self.err(format!(
                "type tree of {count} nodes and {buf_len} string bytes does not fit in the {} bytes left",
                self.left()
            )));
        };
        let nodes_at = self.pos;
        self.pos += count * node_size as usize;
        let buf = self.take(buf_len, "type tree strings")?;
        let strings_end = self.pos;
        self.pos = nodes_at;
        let mut nodes = Vec::with_capacity(count);
        for _ in 0..count {
            let _version = self.u16("type tree node")?;
            let level = self.u8("type tree node")?;
            let type_flags = u32::from(self.u8("type tree node")?);
            let type_offset = self.u32("type tree node")?;
            let name_offset = self.u32("type tree node")?;
            let byte_size = self.i32("type tree node")?;
            let _index = self.i32("type tree node")?;
            let meta_flag = self.u32("type tree node")?;
            if version >= 19 {
                let _ref_type_hash = self.u64("type tree node")?;
            }
            nodes.push(TypeNode {
                type_name: self.tree_string(buf, type_offset)?,
                name: self.tree_string(buf, name_offset)?,
                level,
                type_flags,
                byte_size,
                meta_flag,
            });
        }
        self.pos = strings_end;
        Ok(nodes)
    }

    /// A type tree in the older nested layout (formats 9 and 11), flattened depth first.
    fn nested_tree(&mut self, level: usize, nodes: &mut Vec<TypeNode>) -> Result<()> {
        if level > MAX_DEPTH {
            return Err(self.err(format!("type tree nested deeper than {MAX_DEPTH} levels")));
        }
        let type_name = self.cstr("type tree node type")?;
        let name = self.cstr("type tree node name")?;
        let byte_size = self.i32("type tree node")?;
        let _index = self.i32("type tree node")?;
        let is_array = self.i32("type tree node")?;
        let _version = self.i32("type tree node")?;
        let meta_flag = self.u32("type tree node")?;
        nodes.push(TypeNode {
            type_name,
            name,
            level: level as u8,
            type_flags: u32::from(is_array != 0),
            byte_size,
            meta_flag,
        });
        // A child is at least two NULs and six 4-byte fields.
        let children = self.count(30, "type tree child count")?;
        for _ in 0..children {
            self.nested_tree(level + 1, nodes)?;
        }
        Ok(())
    }
}

/// The `.meta` text of a raw GUID: Unity prints each byte low nibble first.
fn guid_text(raw: &[u8; 16]) -> String {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    raw.iter()
        .flat_map(|&b| [HEX[usize::from(b & 0x0f)], HEX[usize::from(b >> 4)]])
        .map(char::from)
        .collect()
}

impl SerializedFile {
    /// Cheap plausibility check of the header: a known format version, an endianness
    /// byte of 0 or 1, a data offset inside the stated file size, and a Unity version
    /// string that starts with a digit. A text (YAML) asset never passes.
    pub fn is_serialized_file(bytes: &[u8]) -> bool {
        let be32 = |at: usize| {
            bytes
                .get(at..at + 4)
                .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as u64)
        };
        let be64 = |at: usize| {
            bytes.get(at..at + 8).map(|b| {
                let mut a = [0u8; 8];
                a.copy_from_slice(b);
                u64::from_be_bytes(a)
            })
        };
        let Some(version) = be32(8) else {
            return false;
        };
        if !(MIN_VERSION as u64..=MAX_VERSION as u64).contains(&version) {
            return false;
        }
        if !matches!(bytes.get(16), Some(0 | 1)) {
            return false;
        }
        let (file_size, data_offset, header_end) = if version >= 22 {
            (be64(24), be64(32), 48)
        } else {
            (be32(4), be32(12), 20)
        };
        let (Some(file_size), Some(data_offset)) = (file_size, data_offset) else {
            return false;
        };
        data_offset <= file_size
            && file_size >= header_end as u64
            && bytes.get(header_end).is_some_and(u8::is_ascii_digit)
    }

    /// Parses the header and metadata (types, object table, externals). `path` names the
    /// file in errors.
    pub fn parse(bytes: Vec<u8>, path: &str) -> Result<SerializedFile> {
        let mut r = Reader {
            bytes: &bytes,
            pos: 0,
            end: bytes.len(),
            base: 0,
            big: true,
            path,
            budget: 0,
        };
        // The header is big-endian whatever the file's endianness.
        let _metadata_size = r.u32("header")?;
        let mut file_size = u64::from(r.u32("header")?);
        let version = r.u32("header")?;
        let mut data_offset = u64::from(r.u32("header")?);
        if version < MIN_VERSION {
            return Err(SerializedError::TooOld {
                path: path.to_string(),
                version,
            });
        }
        if version > MAX_VERSION {
            return Err(SerializedError::TooNew {
                path: path.to_string(),
                version,
            });
        }
        let big = r.u8("endianness")? != 0;
        r.take(3, "header")?;
        if version >= 22 {
            // 64-bit sizes replace the 32-bit ones.
            let _metadata_size = r.u32("header")?;
            let at = r.pos;
            let size = r.i64("header")?;
            let offset = r.i64("header")?;
            let _unknown = r.i64("header")?;
            let (Ok(size), Ok(offset)) = (u64::try_from(size), u64::try_from(offset)) else {
                r.pos = at;
                return Err(r.err(format!("negative file size {size} or data offset {offset}")));
            };
            (file_size, data_offset) = (size, offset);
        }
        if (bytes.len() as u64) < file_size {
            r.pos = bytes.len();
            return Err(r.err(format!(
                "the header says the file is {file_size} bytes: truncated"
            )));
        }
        r.big = big;

        let unity_version = r.cstr("Unity version")?;
        let _target_platform = r.i32("target platform")?;
        let has_type_trees = version < 13 || r.u8("type tree flag")? != 0;

        // A type is at least its class ID and, with trees, an empty tree.
        let type_min = 4 + if has_type_trees { 8 } else { 0 };
        let type_count = r.count(type_min, "type count")?;
        let mut types = Vec::with_capacity(type_count);
        for _ in 0..type_count {
            let class_id = r.i32("type class ID")?;
            if version >= 16 {
                let _stripped = r.u8("type")?;
            }
            if version >= 17 {
                let _script_type_index = r.i16("type")?;
            }
            if version >= 13 {
                if (version < 16 && class_id < 0) || (version >= 16 && class_id == 114) {
                    r.take(16, "script ID")?;
                }
                r.take(16, "type hash")?;
            }
            let mut tree = TypeTree::default();
            if has_type_trees {
                let at = r.pos;
                let nodes = if version >= 12 || version == 10 {
                    r.blob_tree(version)?
                } else {
                    let mut nodes = Vec::new();
                    r.nested_tree(0, &mut nodes)?;
                    nodes
                };
                tree = TypeTree::new(nodes, |message| SerializedError::Malformed {
                    path: path.to_string(),
                    offset: at as u64,
                    message,
                })?;
                if version >= 21 {
                    let deps = r.count(4, "type dependency count")?;
                    r.take(deps * 4, "type dependencies")?;
                }
            }
            types.push(SerializedType { class_id, tree });
        }

        let big_ids = (7..14).contains(&version) && r.i32("big ID flag")? != 0;
        let object_count = r.count(16, "object count")?;
        let mut objects = Vec::with_capacity(object_count);
        for _ in 0..object_count {
            let path_id = if big_ids {
                r.i64("object path ID")?
            } else if version < 14 {
                i64::from(r.i32("object path ID")?)
            } else {
                r.align4();
                r.i64("object path ID")?
            };
            let byte_start = if version >= 22 {
                let at = r.pos;
                let s = r.i64("object start")?;
                u64::try_from(s).map_err(|_| {
                    r.pos = at;
                    r.err(format!("object {path_id}: negative start {s}"))
                })?
            } else {
                u64::from(r.u32("object start")?)
            };
            let byte_size = r.u32("object size")?;
            let at = r.pos;
            let type_id = r.i32("object type")?;
            let (class_id, type_index) = if version < 16 {
                // Old files list the class ID itself, and the type is the one for it.
                let class_id = i32::from(r.u16("object class ID")?);
                (class_id, types.iter().position(|t| t.class_id == type_id))
            } else {
                match usize::try_from(type_id).ok().filter(|&t| t < types.len()) {
                    Some(t) => (types[t].class_id, Some(t)),
                    None => {
                        r.pos = at;
                        return Err(r.err(format!(
                            "object {path_id}: type index {type_id} is not one of the {} types",
                            types.len()
                        )));
                    }
                }
            };
            if version < 11 {
                let _destroyed = r.u16("object")?;
            }
            if (11..17).contains(&version) {
                let _script_type_index = r.i16("object")?;
            }
            if version == 15 || version == 16 {
                let _stripped = r.u8("object")?;
            }
            objects.push(ObjectInfo {
                path_id,
                class_id,
                byte_start: data_offset.saturating_add(byte_start),
                byte_size,
                type_index,
            });
        }

        if version >= 11 {
            let scripts = r.count(8, "script count")?;
            for _ in 0..scripts {
                let _file_index = r.i32("script")?;
                if version < 14 {
                    let _local_id = r.i32("script")?;
                } else {
                    r.align4();
                    let _local_id = r.i64("script")?;
                }
            }
        }

        let external_count = r.count(22, "external count")?;
        let mut externals = Vec::with_capacity(external_count);
        for _ in 0..external_count {
            let _empty = r.cstr("external")?;
            let guid = guid_text(&r.array::<16>("external GUID")?);
            let _type = r.i32("external")?;
            let path = r.cstr("external path")?;
            externals.push(External { guid, path });
        }

        Ok(SerializedFile {
            version,
            unity_version,
            objects,
            externals,
            types,
            has_type_trees,
            big_endian: big,
            path: path.to_string(),
            bytes,
        })
    }

    /// The object's fields, read through its type's tree (error if the file has no type
    /// tree).
    pub fn read(&self, path_id: i64) -> Result<Value> {
        let Some(obj) = self.objects.iter().find(|o| o.path_id == path_id) else {
            return Err(SerializedError::NoObject {
                path: self.path.clone(),
                path_id,
            });
        };
        let malformed = |message: String| SerializedError::Malformed {
            path: self.path.clone(),
            offset: obj.byte_start,
            message: format!("object {path_id}: {message}"),
        };
        if !self.has_type_trees {
            return Err(SerializedError::NoTypeTree {
                path: self.path.clone(),
                offset: obj.byte_start,
                path_id,
            });
        }
        let Some(ty) = obj.type_index.and_then(|t| self.types.get(t)) else {
            return Err(malformed(format!(
                "class {} has no type in the file",
                obj.class_id
            )));
        };
        if ty.tree.nodes.is_empty() {
            return Err(malformed("its type tree is empty".into()));
        }
        let end = obj.byte_start.checked_add(u64::from(obj.byte_size));
        let (start, end) = match end {
            Some(end) if end <= self.bytes.len() as u64 => (obj.byte_start as usize, end as usize),
            _ => {
                return Err(malformed(format!(
                    "its {} bytes run past the end of the file ({} bytes)",
                    obj.byte_size,
                    self.bytes.len()
                )))
            }
        };
        let mut r = Reader {
            bytes: &self.bytes,
            pos: start,
            end,
            base: start,
            big: self.big_endian,
            path: &self.path,
            // Generous for real trees (a leaf reads at least a byte, and few compounds
            // wrap fewer than a few bytes), small enough to bound a hostile one.
            budget: 16 * u64::from(obj.byte_size) + 4096,
        };
        r.node(&ty.tree, 0, 0)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::path::PathBuf;

    pub(crate) const ALIGN: u32 = ALIGN_BYTES;

    /// A byte writer in the file's endianness.
    pub(crate) struct W {
        pub(crate) buf: Vec<u8>,
        big: bool,
    }

    macro_rules! write_num {
        ($name:ident, $t:ty) => {
            pub(crate) fn $name(&mut self, v: $t) {
                let b = if self.big {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                };
                self.buf.extend_from_slice(&b);
            }
        };
    }

    impl W {
        pub(crate) fn new(big: bool) -> W {
            W {
                buf: Vec::new(),
                big,
            }
        }
        pub(crate) fn u8(&mut self, v: u8) {
            self.buf.push(v);
        }
        write_num!(u16, u16);
        write_num!(i16, i16);
        write_num!(u32, u32);
        write_num!(i32, i32);
        write_num!(i64, i64);
        write_num!(u64, u64);
        write_num!(f32, f32);
        write_num!(f64, f64);
        fn bytes(&mut self, b: &[u8]) {
            self.buf.extend_from_slice(b);
        }
        fn cstr(&mut self, s: &str) {
            self.bytes(s.as_bytes());
            self.u8(0);
        }
        /// Pads to a multiple of 4 from the buffer start.
        pub(crate) fn align(&mut self) {
            while !self.buf.len().is_multiple_of(4) {
                self.u8(0);
            }
        }
        /// A `string` field (its Array node aligns).
        pub(crate) fn string(&mut self, s: &str) {
            self.i32(s.len() as i32);
            self.bytes(s.as_bytes());
            self.align();
        }
    }

    /// (level, type, name, byteSize, typeFlags, metaFlag)
    pub(crate) type NodeSpec = (u8, &'static str, &'static str, i32, u8, u32);

    pub(crate) struct TypeSpec {
        pub(crate) class_id: i32,
        pub(crate) nodes: Vec<NodeSpec>,
    }

    pub(crate) struct ObjSpec {
        pub(crate) path_id: i64,
        pub(crate) type_index: usize,
        pub(crate) data: Vec<u8>,
    }

    /// A `string` field's nodes at `level`.
    pub(crate) fn string_nodes(level: u8, name: &'static str) -> Vec<NodeSpec> {
        vec![
            (level, "string", name, -1, 0, 0x8000),
            (level + 1, "Array", "Array", -1, 1, ALIGN),
            (level + 2, "int", "size", 4, 0, 0),
            (level + 2, "char", "data", 1, 0, 0),
        ]
    }

    fn thing_type() -> TypeSpec {
        let mut n: Vec<NodeSpec> = vec![(0, "Thing", "Base", -1, 0, 0)];
        n.extend(string_nodes(1, "m_Name"));
        n.extend([
            (1, "bool", "m_Flag", 1, 0, ALIGN),
            (1, "Vector3f", "m_Scale", 12, 0, 0),
            (2, "float", "x", 4, 0, 0),
            (2, "float", "y", 4, 0, 0),
            (2, "float", "z", 4, 0, 0),
            (1, "vector", "m_Heights", -1, 0, 0),
            (2, "Array", "Array", -1, 1, ALIGN),
            (3, "int", "size", 4, 0, 0),
            (3, "SInt16", "data", 2, 0, 0),
            (1, "PPtr<Object>", "m_Ref", 12, 0, 0),
            (2, "int", "m_FileID", 4, 0, 0),
            (2, "SInt64", "m_PathID", 8, 0, 0),
            (1, "vector", "m_Layers", -1, 0, 0),
            (2, "Array", "Array", -1, 1, 0),
            (3, "int", "size", 4, 0, 0),
            (3, "Layer", "data", -1, 0, 0),
        ]);
        n.extend(string_nodes(4, "m_Name"));
        n.extend([
            (4, "float", "m_Weight", 4, 0, 0),
            (4, "UInt8", "m_On", 1, 0, ALIGN),
            (1, "vector", "m_Mask", -1, 0, 0),
            (2, "Array", "Array", -1, 1, ALIGN),
            (3, "int", "size", 4, 0, 0),
            (3, "bool", "data", 1, 0, 0),
            (1, "map", "m_Lookup", -1, 0, 0),
            (2, "Array", "Array", -1, 1, 0),
            (3, "int", "size", 4, 0, 0),
            (3, "pair", "data", -1, 0, 0),
        ]);
        n.extend(string_nodes(4, "first"));
        n.extend([
            (4, "int", "second", 4, 0, 0),
            (1, "TypelessData", "m_Data", -1, 1, ALIGN),
            (2, "int", "size", 4, 0, 0),
            (2, "UInt8", "data", 1, 0, 0),
            (1, "UInt64", "m_Big", 8, 0, 0),
            (1, "double", "m_Double", 8, 0, 0),
            (1, "Weird", "m_Weird", 2, 0, ALIGN),
            (1, "vector", "m_Bytes", -1, 0, 0),
            (2, "Array", "Array", -1, 1, ALIGN),
            (3, "int", "size", 4, 0, 0),
            (3, "SInt8", "data", 1, 0, 0),
        ]);
        TypeSpec {
            class_id: 1001,
            nodes: n,
        }
    }

    fn game_object_type() -> TypeSpec {
        let mut n: Vec<NodeSpec> = vec![(0, "GameObject", "Base", -1, 0, 0)];
        n.extend(string_nodes(1, "m_Name"));
        n.push((1, "unsigned int", "m_Layer", 4, 0, 0));
        TypeSpec {
            class_id: 1,
            nodes: n,
        }
    }

    /// A Thing's data; `heights` and `layers` override the written counts.
    fn thing_data(big: bool, heights: i32, layers: i32) -> Vec<u8> {
        let mut w = W::new(big);
        w.string("abc");
        w.u8(1);
        w.align();
        w.f32(1.5);
        w.f32(-2.0);
        w.f32(0.25);
        w.i32(heights);
        for h in [-3i16, 0, 7, i16::MAX, i16::MIN] {
            w.i16(h);
        }
        w.align();
        w.i32(1);
        w.i64(-1_234_567_890_123);
        w.i32(layers);
        for (name, weight, on) in [("ground", 0.5f32, 1u8), ("rock!", 2.0, 0)] {
            w.string(name);
            w.f32(weight);
            w.u8(on);
            w.align();
        }
        w.i32(3);
        w.bytes(&[1, 0, 1]);
        w.align();
        w.i32(1);
        w.string("k");
        w.i32(42);
        w.i32(5);
        w.bytes(&[1, 2, 3, 4, 5]);
        w.align();
        w.u64(u64::MAX);
        w.f64(-0.125);
        w.u16(0xbeef);
        w.align();
        w.i32(2);
        w.bytes(&[0xff, 0x7f]);
        w.align();
        w.buf
    }

    fn thing_value() -> Value {
        let s = |v: &str| Value::Str(v.to_string());
        let map = |kv: Vec<(&str, Value)>| {
            Value::Map(kv.into_iter().map(|(k, v)| (k.to_string(), v)).collect())
        };
        map(vec![
            ("m_Name", s("abc")),
            ("m_Flag", Value::Bool(true)),
            (
                "m_Scale",
                map(vec![
                    ("x", Value::Float(1.5)),
                    ("y", Value::Float(-2.0)),
                    ("z", Value::Float(0.25)),
                ]),
            ),
            (
                "m_Heights",
                Value::Numbers(vec![-3.0, 0.0, 7.0, 32767.0, -32768.0]),
            ),
            (
                "m_Ref",
                map(vec![
                    ("m_FileID", Value::Int(1)),
                    ("m_PathID", Value::Int(-1_234_567_890_123)),
                ]),
            ),
            (
                "m_Layers",
                Value::Seq(vec![
                    map(vec![
                        ("m_Name", s("ground")),
                        ("m_Weight", Value::Float(0.5)),
                        ("m_On", Value::Int(1)),
                    ]),
                    map(vec![
                        ("m_Name", s("rock!")),
                        ("m_Weight", Value::Float(2.0)),
                        ("m_On", Value::Int(0)),
                    ]),
                ]),
            ),
            (
                "m_Mask",
                Value::Seq(vec![
                    Value::Bool(true),
                    Value::Bool(false),
                    Value::Bool(true),
                ]),
            ),
            (
                "m_Lookup",
                Value::Seq(vec![map(vec![
                    ("first", s("k")),
                    ("second", Value::Int(42)),
                ])]),
            ),
            ("m_Data", Value::Bytes(vec![1, 2, 3, 4, 5])),
            ("m_Big", Value::Int(-1)),
            ("m_Double", Value::Float(-0.125)),
            ("m_Weird", Value::Int(0xbeef)),
            ("m_Bytes", Value::Bytes(vec![0xff, 0x7f])),
        ])
    }

    fn game_object_data(big: bool) -> Vec<u8> {
        let mut w = W::new(big);
        w.string("Hero");
        w.u32(3_000_000_000);
        w.buf
    }

    /// The raw bytes of the test external's GUID, and its `.meta` text.
    pub(crate) const GUID_RAW: [u8; 16] = [
        0x10, 0x32, 0x54, 0x76, 0x98, 0xba, 0xdc, 0xfe, 0x01, 0x23, 0x45, 0x67, 0x89, 0xab, 0xcd,
        0xef,
    ];
    pub(crate) const GUID_TEXT: &str = "0123456789abcdef1032547698badcfe";

    /// A blob type tree; strings in Unity's common table are written by common offset.
    fn write_tree(w: &mut W, version: u32, nodes: &[NodeSpec]) {
        let mut local: Vec<u8> = Vec::new();
        let mut offset = |s: &str| -> u32 {
            let table = COMMON_STRINGS.as_bytes();
            if let Some(at) = (0..table.len()).find(|&at| common_string(at as u32) == Some(s)) {
                return COMMON_BIT | at as u32;
            }
            let at = local.len() as u32;
            local.extend_from_slice(s.as_bytes());
            local.push(0);
            at
        };
        let offsets: Vec<(u32, u32)> = nodes
            .iter()
            .map(|&(_, t, n, ..)| (offset(t), offset(n)))
            .collect();
        w.i32(nodes.len() as i32);
        w.i32(local.len() as i32);
        for (i, &(level, _, _, size, flags, meta)) in nodes.iter().enumerate() {
            w.u16(1);
            w.u8(level);
            w.u8(flags);
            w.u32(offsets[i].0);
            w.u32(offsets[i].1);
            w.i32(size);
            w.i32(i as i32);
            w.u32(meta);
            if version >= 19 {
                w.u64(0);
            }
        }
        w.bytes(&local);
    }

    /// A serialized file of format `version` holding `types` (with trees when `trees`),
    /// `objects` and one external.
    pub(crate) fn file(
        version: u32,
        big: bool,
        trees: bool,
        types: &[TypeSpec],
        objects: &[ObjSpec],
    ) -> Vec<u8> {
        let header_len = if version >= 22 { 48 } else { 20 };
        let mut w = W::new(big);
        w.bytes(&vec![0; header_len]);
        let metadata_start = w.buf.len();
        w.cstr("5.6.3p1");
        w.i32(19);
        if version >= 13 {
            w.u8(u8::from(trees));
        }
        w.i32(types.len() as i32);
        for t in types {
            w.i32(t.class_id);
            if version >= 16 {
                w.u8(0);
            }
            if version >= 17 {
                w.i16(-1);
            }
            if version >= 13 {
                if (version < 16 && t.class_id < 0) || (version >= 16 && t.class_id == 114) {
                    w.bytes(&[7; 16]);
                }
                w.bytes(&[9; 16]);
            }
            if trees {
                write_tree(&mut w, version, &t.nodes);
                if version >= 21 {
                    w.i32(1);
                    w.i32(0);
                }
            }
        }
        if (7..14).contains(&version) {
            w.i32(0);
        }
        // Objects at 8-byte boundaries of the data section.
        let mut starts = Vec::new();
        let mut data_len = 0usize;
        for o in objects {
            starts.push(data_len);
            data_len = (data_len + o.data.len()).next_multiple_of(8);
        }
        w.i32(objects.len() as i32);
        for (o, &start) in objects.iter().zip(&starts) {
            if version < 14 {
                w.i32(o.path_id as i32);
            } else {
                w.align();
                w.i64(o.path_id);
            }
            if version >= 22 {
                w.i64(start as i64);
            } else {
                w.u32(start as u32);
            }
            w.u32(o.data.len() as u32);
            let class_id = types[o.type_index].class_id;
            if version >= 16 {
                w.i32(o.type_index as i32);
            } else {
                w.i32(class_id);
                w.u16(class_id as u16);
            }
            if version < 11 {
                w.u16(0);
            }
            if (11..17).contains(&version) {
                w.i16(-1);
            }
            if version == 15 || version == 16 {
                w.u8(0);
            }
        }
        if version >= 11 {
            w.i32(1);
            w.i32(0);
            if version < 14 {
                w.i32(11500000);
            } else {
                w.align();
                w.i64(11500000);
            }
        }
        w.i32(1);
        w.cstr("");
        w.bytes(&GUID_RAW);
        w.i32(3);
        w.cstr("Library/unity default resources");
        let metadata_size = (w.buf.len() - metadata_start) as u32;
        while !w.buf.len().is_multiple_of(16) {
            w.u8(0);
        }
        let data_offset = w.buf.len();
        for (o, &start) in objects.iter().zip(&starts) {
            w.buf.resize(data_offset + start, 0);
            w.bytes(&o.data);
        }
        let file_size = w.buf.len();
        // The header is big-endian.
        let mut h = W::new(true);
        if version >= 22 {
            h.bytes(&[0; 8]);
            h.u32(version);
            h.bytes(&[0; 4]);
            h.u8(u8::from(big));
            h.bytes(&[0; 3]);
            h.u32(metadata_size);
            h.i64(file_size as i64);
            h.i64(data_offset as i64);
            h.i64(0);
        } else {
            h.u32(metadata_size);
            h.u32(file_size as u32);
            h.u32(version);
            h.u32(data_offset as u32);
            h.u8(u8::from(big));
            h.bytes(&[0; 3]);
        }
        w.buf[..header_len].copy_from_slice(&h.buf);
        w.buf
    }

    const THING_ID: i64 = 1;
    const GO_ID: i64 = -(1 << 40);

    fn synthetic_with(version: u32, big: bool, trees: bool, heights: i32, layers: i32) -> Vec<u8> {
        file(
            version,
            big,
            trees,
            &[game_object_type(), thing_type()],
            &[
                ObjSpec {
                    path_id: THING_ID,
                    type_index: 1,
                    data: thing_data(big, heights, layers),
                },
                ObjSpec {
                    path_id: if version < 14 { -7 } else { GO_ID },
                    type_index: 0,
                    data: game_object_data(big),
                },
            ],
        )
    }

    fn synthetic(version: u32, big: bool) -> Vec<u8> {
        synthetic_with(version, big, true, 5, 2)
    }

    fn is_malformed(e: &SerializedError) -> bool {
        matches!(e, SerializedError::Malformed { .. })
    }

    #[test]
    fn reads_every_field() {
        for (version, big) in [
            (15, false),
            (17, false),
            (19, false),
            (21, false),
            (22, false),
            (17, true),
            (22, true),
        ] {
            let case = format!("version {version}, big endian {big}");
            let bytes = synthetic(version, big);
            assert!(SerializedFile::is_serialized_file(&bytes), "{case}");
            let f = SerializedFile::parse(bytes, "Assets/Thing.asset").unwrap();
            assert_eq!(f.version, version, "{case}");
            assert_eq!(f.unity_version, "5.6.3p1", "{case}");
            let ids: Vec<(i64, i32)> = f.objects.iter().map(|o| (o.path_id, o.class_id)).collect();
            assert_eq!(ids, [(THING_ID, 1001), (GO_ID, 1)], "{case}");
            assert_eq!(
                f.externals,
                [External {
                    guid: GUID_TEXT.to_string(),
                    path: "Library/unity default resources".to_string(),
                }],
                "{case}"
            );
            assert_eq!(f.read(THING_ID).unwrap(), thing_value(), "{case}");
            let go = f.read(GO_ID).unwrap();
            assert_eq!(go.get("m_Name").and_then(Value::as_str), Some("Hero"));
            assert_eq!(
                go.get("m_Layer").and_then(Value::as_i64),
                Some(3_000_000_000)
            );
            let thing = f.read(THING_ID).unwrap();
            assert_eq!(
                thing.path(&["m_Ref", "m_PathID"]).and_then(Value::as_i64),
                Some(-1_234_567_890_123)
            );
            assert_eq!(
                thing.path(&["m_Scale", "y"]).and_then(Value::as_f64),
                Some(-2.0)
            );
            assert!(thing.path(&["m_Scale", "w"]).is_none());
            assert!(matches!(
                f.read(12345),
                Err(SerializedError::NoObject { path_id: 12345, .. })
            ));
        }
    }

    #[test]
    fn guid_text_swaps_nibbles() {
        assert_eq!(guid_text(&GUID_RAW), GUID_TEXT);
        // The built-in resources file, whose .meta-style GUID is 0000000000000000e000000000000000.
        let mut raw = [0u8; 16];
        raw[8] = 0x0e;
        assert_eq!(guid_text(&raw), "0000000000000000e000000000000000");
    }

    #[test]
    fn common_strings_resolve_by_offset() {
        assert_eq!(common_string(427), Some("m_Name"));
        assert_eq!(common_string(0), Some("AABB"));
        assert_eq!(common_string(49), Some("Array"));
        assert_eq!(common_string(633), Some("PPtr<Object>"));
        assert_eq!(common_string(1152), Some("FileSize"));
        assert_eq!(common_string(1169), Some("RenderingLayerMask"));
        // Inside a string, and past the table.
        assert_eq!(common_string(428), None);
        assert_eq!(common_string(1188), None);
        assert_eq!(common_string(u32::MAX), None);
    }

    /// A format 17 file of one type with `nodes` and one object of four zero bytes.
    fn one_object(nodes: Vec<NodeSpec>) -> Vec<u8> {
        let types = [TypeSpec {
            class_id: 1001,
            nodes,
        }];
        let objects = [ObjSpec {
            path_id: 1,
            type_index: 0,
            data: vec![0; 4],
        }];
        file(17, false, true, &types, &objects)
    }

    #[test]
    fn unknown_common_string_is_an_error() {
        let nodes = vec![(0, "Thing", "Base", -1, 0, 0), (1, "int", "m_X", 4, 0, 0)];
        let mut bytes = one_object(nodes);
        // The "int" type offset (222 | top bit) becomes 223, the middle of a string.
        let needle = (COMMON_BIT | 222).to_le_bytes();
        let at = bytes.windows(4).position(|w| w == needle).unwrap();
        bytes[at] = 223;
        let e = SerializedFile::parse(bytes, "x.asset").unwrap_err();
        assert!(e.to_string().contains("common string offset 223"), "{e}");
    }

    #[test]
    fn every_truncation_is_an_error() {
        for (version, big) in [(17, false), (22, false), (17, true), (15, false)] {
            let full = synthetic(version, big);
            let mut parsed = 0;
            for n in 0..full.len() {
                assert!(
                    SerializedFile::parse(full[..n].to_vec(), "t.asset").is_err(),
                    "version {version}: prefix {n}"
                );
                // With the header's size made to agree, the metadata or the last object
                // is cut instead.
                let mut cut = full[..n].to_vec();
                if version >= 22 && n >= 32 {
                    cut[24..32].copy_from_slice(&(n as i64).to_be_bytes());
                } else if version < 22 && n >= 8 {
                    cut[4..8].copy_from_slice(&(n as u32).to_be_bytes());
                }
                if let Ok(f) = SerializedFile::parse(cut, "t.asset") {
                    parsed += 1;
                    for o in &f.objects {
                        let _ = f.read(o.path_id);
                    }
                    let last = f.objects.last().map(|o| o.path_id).unwrap();
                    assert!(f.read(last).is_err(), "version {version}: prefix {n}");
                }
            }
            // Every cut inside the object data parses and is caught by the read.
            assert!(parsed > 100, "version {version}: {parsed} prefixes parsed");
        }
    }

    #[test]
    fn huge_counts_are_errors() {
        let start = std::time::Instant::now();
        for (heights, layers) in [(i32::MAX, 2), (5, i32::MAX), (-1, 2), (5, 100_000_000)] {
            let f = SerializedFile::parse(synthetic_with(17, false, true, heights, layers), "h")
                .unwrap();
            let e = f.read(THING_ID).unwrap_err();
            assert!(is_malformed(&e), "{e}");
            assert!(e.to_string().starts_with("h: byte "), "{e}");
        }
        // A huge type count in the metadata (just after the version string, platform and
        // tree flag).
        let mut bytes = synthetic(17, false);
        let at = 20 + "5.6.3p1".len() + 1 + 4 + 1;
        bytes[at..at + 4].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(SerializedFile::parse(bytes, "h").is_err());
        assert!(start.elapsed().as_secs() < 2);
    }

    #[test]
    fn no_type_tree_is_reported() {
        let f = SerializedFile::parse(synthetic_with(17, false, false, 5, 2), "p").unwrap();
        assert_eq!(f.objects.len(), 2);
        assert!(matches!(
            f.read(THING_ID),
            Err(SerializedError::NoTypeTree {
                path_id: THING_ID,
                ..
            })
        ));
    }

    #[test]
    fn deep_trees_are_refused() {
        let names: Vec<&'static str> = (0..100).map(|_| "Nest").collect();
        let mut nodes: Vec<NodeSpec> = names
            .iter()
            .enumerate()
            .map(|(i, &t)| (i as u8, t, "m_Child", -1, 0, 0))
            .collect();
        nodes.push((100, "int", "m_X", 4, 0, 0));
        let bytes = one_object(nodes);
        let f = SerializedFile::parse(bytes, "d").unwrap();
        let e = f.read(1).unwrap_err();
        assert!(e.to_string().contains("deeper than 64"), "{e}");
    }

    #[test]
    fn old_and_text_files_are_refused() {
        let mut bytes = synthetic(17, false);
        bytes[8..12].copy_from_slice(&8u32.to_be_bytes());
        assert!(!SerializedFile::is_serialized_file(&bytes));
        let e = SerializedFile::parse(bytes, "o.asset").unwrap_err();
        assert_eq!(
            e.to_string(),
            "o.asset: byte 8: serialized format version 8 is older than Unity 5"
        );
        let yaml = b"%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!156 &15600000\n";
        assert!(!SerializedFile::is_serialized_file(yaml));
        assert!(SerializedFile::parse(yaml.to_vec(), "y").is_err());
        assert!(!SerializedFile::is_serialized_file(&[]));
    }

    /// Check the `unity_serialized` fuzz target's seed `name` against `bytes`: a stale seed
    /// fails; `UNITRACE_WRITE_FUZZ_SEEDS=1` rewrites it.
    pub(crate) fn check_fuzz_seed(name: &str, bytes: &[u8]) {
        let dir =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus/unity_serialized");
        let path = dir.join(name);
        if std::env::var_os("UNITRACE_WRITE_FUZZ_SEEDS").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, bytes).unwrap();
        }
        let on_disk = std::fs::read(&path).unwrap_or_default();
        assert!(
            on_disk == bytes,
            "{} is stale: UNITRACE_WRITE_FUZZ_SEEDS=1 cargo test -p unity --lib seed",
            path.display()
        );
    }

    /// The fuzz target's seeds of the reader alone: the synthetic files above.
    #[test]
    fn fuzz_seeds_are_current() {
        check_fuzz_seed("seed-v17.bin", &synthetic(17, false));
        check_fuzz_seed("seed-v22.bin", &synthetic(22, false));
        check_fuzz_seed("seed-v17-big.bin", &synthetic(17, true));
    }
}
