//! A parser for the YAML subset Unity writes: block mappings, `- ` sequences (at the
//! parent key's indentation, as Unity writes them), flow mappings and sequences that may
//! wrap onto following lines, and plain scalars.
//!
//! Unity's files are not valid YAML for a strict parser (` stripped` headers, a `%TAG`
//! that covers only the first document, repeated `data:` keys in old materials), so each
//! document body is parsed alone by this small parser. Mappings keep their keys in order
//! and keep duplicates.

use glam::{Quat, Vec3, Vec4};

#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    Scalar(String),
    Map(Vec<(String, Node)>),
    Seq(Vec<Node>),
}

static EMPTY_SEQ: &[Node] = &[];

impl Node {
    /// First value under `key` (mappings only).
    pub fn get(&self, key: &str) -> Option<&Node> {
        match self {
            Node::Map(kv) => kv.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// Every value under `key` (old materials repeat `data:`).
    pub fn get_all<'a>(&'a self, key: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        let kv: &[(String, Node)] = match self {
            Node::Map(kv) => kv,
            _ => &[],
        };
        kv.iter().filter(move |(k, _)| k == key).map(|(_, v)| v)
    }

    /// Follow a path of keys.
    pub fn path(&self, keys: &[&str]) -> Option<&Node> {
        keys.iter().try_fold(self, |n, k| n.get(k))
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            Node::Scalar(s) => Some(s),
            _ => None,
        }
    }

    pub fn as_seq(&self) -> &[Node] {
        match self {
            Node::Seq(v) => v,
            _ => EMPTY_SEQ,
        }
    }

    pub fn as_map(&self) -> &[(String, Node)] {
        match self {
            Node::Map(kv) => kv,
            _ => &[],
        }
    }

    pub fn as_f32(&self) -> Option<f32> {
        self.as_str().and_then(parse_f32)
    }

    pub fn as_i64(&self) -> Option<i64> {
        let s = self.as_str()?.trim();
        s.parse::<i64>()
            .ok()
            .or_else(|| s.parse::<u64>().ok().map(|u| u as i64))
            .or_else(|| parse_f32(s).filter(|f| f.fract() == 0.0).map(|f| f as i64))
    }

    /// `key` as a float, if present and numeric.
    pub fn f32_at(&self, key: &str) -> Option<f32> {
        self.get(key).and_then(Node::as_f32)
    }

    pub fn i64_at(&self, key: &str) -> Option<i64> {
        self.get(key).and_then(Node::as_i64)
    }

    pub fn str_at(&self, key: &str) -> Option<&str> {
        self.get(key).and_then(Node::as_str)
    }

    /// `{x: …, y: …, z: …}`.
    pub fn vec3(&self) -> Option<Vec3> {
        Some(Vec3::new(
            self.f32_at("x")?,
            self.f32_at("y")?,
            self.f32_at("z")?,
        ))
    }

    /// `{x: …, y: …, z: …, w: …}` as a quaternion (not normalised here).
    pub fn quat(&self) -> Option<Quat> {
        Some(Quat::from_xyzw(
            self.f32_at("x")?,
            self.f32_at("y")?,
            self.f32_at("z")?,
            self.f32_at("w")?,
        ))
    }

    /// `{r: …, g: …, b: …, a: …}` (alpha defaults to 1).
    pub fn color(&self) -> Option<Vec4> {
        Some(Vec4::new(
            self.f32_at("r")?,
            self.f32_at("g")?,
            self.f32_at("b")?,
            self.f32_at("a").unwrap_or(1.0),
        ))
    }
}

/// A float as Unity writes it: `1.5`, `.5`, `-1e-05`, or `0x3fc00000(1.5)` where the hex
/// bits are authoritative.
pub fn parse_f32(s: &str) -> Option<f32> {
    let s = s.trim();
    if let Some(hex) = s.strip_prefix("0x") {
        let end = hex.find('(').unwrap_or(hex.len());
        return u32::from_str_radix(&hex[..end], 16)
            .ok()
            .map(f32::from_bits);
    }
    match s {
        "Infinity" | "inf" => Some(f32::INFINITY),
        "-Infinity" | "-inf" => Some(f32::NEG_INFINITY),
        "NaN" | "nan" => Some(f32::NAN),
        _ => s.parse::<f32>().ok(),
    }
}

struct Line {
    indent: usize,
    text: String,
}

/// Parse one document body (the lines after a `--- !u!` header).
pub fn parse(text: &str) -> Node {
    let lines = logical_lines(text);
    let mut p = Parser {
        lines,
        pos: 0,
        depth: 0,
    };
    if p.lines.is_empty() {
        return Node::Map(vec![]);
    }
    let indent = p.lines[0].indent;
    p.node(indent)
}

/// The first sign that a document body is not YAML as Unity writes it: a flow
/// collection that is never closed or closes more than it opened, or a line that is
/// neither `key: value` nor a list item. Returns the 1-based line within `text` and what
/// is wrong. [`parse`] still reads what it can of such a body; this lets the converter
/// say which document it had to guess at.
pub fn malformed(text: &str) -> Option<(usize, String)> {
    let mut depth: i64 = 0;
    let mut opened = 0usize;
    // Indent of the previous structural line, and whether it ended with `:`.
    let mut prev: Option<(usize, bool)> = None;
    for (i, raw) in text.lines().enumerate() {
        let raw = raw.trim_end_matches('\r');
        let t = raw.trim_start_matches(' ');
        if depth > 0 {
            depth += bracket_balance(t);
            if depth < 0 {
                return Some((i + 1, "a flow collection closes more than it opened".into()));
            }
            continue;
        }
        if t.is_empty() || t.starts_with('#') || t.starts_with('%') {
            continue;
        }
        let indent = raw.len() - t.len();
        let structural = looks_structural(t);
        if let Some((pi, colon)) = prev {
            // A deeper plain line continues a multi-line scalar (see logical_lines).
            if indent > pi && !structural && !colon {
                continue;
            }
        }
        if !structural {
            let shown: String = t.chars().take(40).collect();
            return Some((
                i + 1,
                format!("`{shown}` is neither `key: value` nor a list item"),
            ));
        }
        if let Some(v) = flow_value(t) {
            let b = bracket_balance(v);
            if b < 0 {
                return Some((i + 1, "a flow collection closes more than it opened".into()));
            }
            if b > 0 {
                depth = b;
                opened = i + 1;
            }
        }
        prev = Some((indent, t.ends_with(':')));
    }
    (depth > 0).then(|| {
        (
            opened,
            "a flow collection opened here is never closed".into(),
        )
    })
}

/// Split into lines, dropping blanks and comments, and join flow collections that wrap
/// onto following lines (Unity wraps long `{fileID: …, guid: …, type: 3}` values).
fn logical_lines(text: &str) -> Vec<Line> {
    let mut out: Vec<Line> = Vec::new();
    let mut depth: i64 = 0;
    for raw in text.lines() {
        let raw = raw.trim_end_matches('\r');
        let trimmed = raw.trim_start_matches(' ');
        if depth > 0 {
            if let Some(last) = out.last_mut() {
                last.text.push(' ');
                last.text.push_str(trimmed.trim());
            }
            depth += bracket_balance(trimmed);
            continue;
        }
        if trimmed.is_empty() || trimmed.starts_with('#') || trimmed.starts_with('%') {
            continue;
        }
        let indent = raw.len() - trimmed.len();
        // A line deeper than the previous one that is neither a key nor a list item
        // continues a multi-line plain scalar: fold it in.
        if let Some(last) = out.last_mut() {
            if indent > last.indent && !looks_structural(trimmed) && !last.text.ends_with(':') {
                last.text.push(' ');
                last.text.push_str(trimmed.trim());
                continue;
            }
        }
        depth = flow_value(trimmed).map_or(0, |v| bracket_balance(v).max(0));
        out.push(Line {
            indent,
            text: trimmed.to_string(),
        });
    }
    out
}

/// The value of a line when it is a flow collection (`key: {…`, `- {…`, `- key: [..`):
/// only those can wrap onto the next line. Braces inside plain scalars (names) do not.
fn flow_value(t: &str) -> Option<&str> {
    let mut v = t;
    while let Some(rest) = v.strip_prefix("- ") {
        v = rest.trim_start();
    }
    if let Some((_, value)) = split_key(v) {
        v = value;
    }
    (v.starts_with('{') || v.starts_with('[')).then_some(v)
}

fn looks_structural(t: &str) -> bool {
    t.starts_with("- ") || t == "-" || split_key(t).is_some()
}

/// Net count of open flow brackets outside quotes.
fn bracket_balance(s: &str) -> i64 {
    let mut d = 0i64;
    let mut quote: Option<char> = None;
    for c in s.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '\'' | '"') => quote = Some(c),
            (None, '{' | '[') => d += 1,
            (None, '}' | ']') => d -= 1,
            _ => {}
        }
    }
    d
}

/// `key: value` or `key:` → (key, value). Keys may contain spaces (`field of view`).
fn split_key(t: &str) -> Option<(&str, &str)> {
    if t.starts_with('{') || t.starts_with('[') || t.starts_with('"') || t.starts_with('\'') {
        return None;
    }
    if let Some(i) = t.find(": ") {
        return Some((&t[..i], t[i + 2..].trim()));
    }
    t.strip_suffix(':').map(|k| (k, ""))
}

struct Parser {
    lines: Vec<Line>,
    pos: usize,
    depth: u32,
}

impl Parser {
    fn is_item(&self, i: usize) -> bool {
        let t = &self.lines[i].text;
        t == "-" || t.starts_with("- ")
    }

    fn node(&mut self, indent: usize) -> Node {
        // Unity documents nest a handful of levels; a pathological file must not
        // exhaust the stack: skip what lies deeper than any Unity file goes.
        if self.depth > 128 {
            while self.pos < self.lines.len() && self.lines[self.pos].indent >= indent {
                self.pos += 1;
            }
            return Node::Scalar(String::new());
        }
        self.depth += 1;
        let n = if self.pos < self.lines.len() && self.is_item(self.pos) {
            self.seq(indent)
        } else {
            self.map(indent)
        };
        self.depth -= 1;
        n
    }

    fn map(&mut self, indent: usize) -> Node {
        let mut kv = Vec::new();
        while self.pos < self.lines.len() {
            let line = &self.lines[self.pos];
            if line.indent < indent || (line.indent == indent && self.is_item(self.pos)) {
                break;
            }
            if line.indent > indent {
                // Stray deeper line: not ours to interpret.
                self.pos += 1;
                continue;
            }
            let Some((k, v)) = split_key(&line.text) else {
                self.pos += 1;
                continue;
            };
            let (key, value) = (k.to_string(), v.to_string());
            self.pos += 1;
            let node = if !value.is_empty() {
                inline(&value)
            } else if self.pos < self.lines.len()
                && (self.lines[self.pos].indent > indent
                    || (self.lines[self.pos].indent == indent && self.is_item(self.pos)))
            {
                let ind = self.lines[self.pos].indent;
                self.node(ind)
            } else {
                Node::Scalar(String::new())
            };
            kv.push((key, node));
        }
        Node::Map(kv)
    }

    fn seq(&mut self, indent: usize) -> Node {
        let mut items = Vec::new();
        while self.pos < self.lines.len()
            && self.lines[self.pos].indent == indent
            && self.is_item(self.pos)
        {
            let text = self.lines[self.pos].text.clone();
            let rest = text[1..].trim_start();
            if rest.is_empty() {
                self.pos += 1;
                if self.pos < self.lines.len() && self.lines[self.pos].indent > indent {
                    let ind = self.lines[self.pos].indent;
                    items.push(self.node(ind));
                } else {
                    items.push(Node::Scalar(String::new()));
                }
            } else if split_key(rest).is_some() || rest.starts_with("- ") {
                // `- key: value` starts a mapping whose further keys sit under `key`.
                let inner = indent + (text.len() - rest.len());
                self.lines[self.pos] = Line {
                    indent: inner,
                    text: rest.to_string(),
                };
                items.push(self.node(inner));
            } else {
                items.push(inline(rest));
                self.pos += 1;
            }
        }
        Node::Seq(items)
    }
}

/// A value written on the key's line: flow mapping, flow sequence or scalar.
fn inline(s: &str) -> Node {
    let mut f = Flow {
        s: s.as_bytes(),
        i: 0,
        depth: 0,
    };
    f.value(true)
}

struct Flow<'a> {
    s: &'a [u8],
    i: usize,
    depth: u32,
}

impl Flow<'_> {
    fn ws(&mut self) {
        while self.i < self.s.len() && (self.s[self.i] == b' ' || self.s[self.i] == b'\t') {
            self.i += 1;
        }
    }

    fn value(&mut self, top: bool) -> Node {
        self.ws();
        // Unity nests flow collections two or three deep; anything far deeper is not a
        // Unity file, and is kept as text rather than recursed into.
        self.depth += 1;
        if self.depth > 64 {
            self.depth -= 1;
            let rest = String::from_utf8_lossy(&self.s[self.i..]).to_string();
            self.i = self.s.len();
            return Node::Scalar(rest);
        }
        let v = self.value_inner(top);
        self.depth -= 1;
        v
    }

    fn value_inner(&mut self, top: bool) -> Node {
        match self.s.get(self.i) {
            Some(b'{') => {
                self.i += 1;
                let mut kv = Vec::new();
                loop {
                    self.ws();
                    match self.s.get(self.i) {
                        None => break,
                        Some(b'}') => {
                            self.i += 1;
                            break;
                        }
                        Some(b',') => {
                            self.i += 1;
                            continue;
                        }
                        _ => {}
                    }
                    let start = self.i;
                    while self.i < self.s.len() && !matches!(self.s[self.i], b':' | b',' | b'}') {
                        self.i += 1;
                    }
                    let key = String::from_utf8_lossy(&self.s[start..self.i])
                        .trim()
                        .to_string();
                    if self.s.get(self.i) == Some(&b':') {
                        self.i += 1;
                        let v = self.value(false);
                        kv.push((key, v));
                    } else {
                        kv.push((key, Node::Scalar(String::new())));
                    }
                }
                Node::Map(kv)
            }
            Some(b'[') => {
                self.i += 1;
                let mut items = Vec::new();
                loop {
                    self.ws();
                    match self.s.get(self.i) {
                        None => break,
                        Some(b']') => {
                            self.i += 1;
                            break;
                        }
                        Some(b',') => {
                            self.i += 1;
                            continue;
                        }
                        _ => {
                            let at = self.i;
                            items.push(self.value(false));
                            // A stray `}` ends a scalar without being consumed; step over
                            // it, or `[a}` would loop forever (found by fuzzing).
                            if self.i == at {
                                self.i += 1;
                            }
                        }
                    }
                }
                Node::Seq(items)
            }
            Some(&q) if q == b'"' || q == b'\'' => {
                self.i += 1;
                let start = self.i;
                while self.i < self.s.len() && self.s[self.i] != q {
                    self.i += 1;
                }
                let v = String::from_utf8_lossy(&self.s[start..self.i]).to_string();
                self.i = (self.i + 1).min(self.s.len());
                Node::Scalar(v)
            }
            _ => {
                let start = self.i;
                if top {
                    self.i = self.s.len();
                } else {
                    while self.i < self.s.len() && !matches!(self.s[self.i], b',' | b'}' | b']') {
                        self.i += 1;
                    }
                }
                Node::Scalar(
                    String::from_utf8_lossy(&self.s[start..self.i])
                        .trim()
                        .to_string(),
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unity_subset() {
        let body = "Transform:\n  m_GameObject: {fileID: 12}\n  m_LocalRotation: {x: 0, y: 0.7071068, z: 0,\n    w: 0.7071068}\n  m_LocalPosition: {x: .5, y: 0x3fc00000(1.5), z: -2}\n  m_Children:\n  - {fileID: 5}\n  - {fileID: -9223372036854775807}\n  m_Component:\n  - component: {fileID: 7}\n  - 4: {fileID: 8}\n  field of view: 60\n  m_Name: My Thing: 2\n  empty:\n  guid: 0000000000000000e000000000000000\n";
        let n = parse(body);
        let t = n.get("Transform").unwrap();
        assert_eq!(
            t.path(&["m_GameObject", "fileID"]).unwrap().as_i64(),
            Some(12)
        );
        let q = t.get("m_LocalRotation").unwrap().quat().unwrap();
        assert!((q.w - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-7);
        let p = t.get("m_LocalPosition").unwrap().vec3().unwrap();
        assert_eq!(p, Vec3::new(0.5, 1.5, -2.0));
        let ch = t.get("m_Children").unwrap().as_seq();
        assert_eq!(ch.len(), 2);
        assert_eq!(ch[1].i64_at("fileID"), Some(-9223372036854775807));
        let comps = t.get("m_Component").unwrap().as_seq();
        assert_eq!(
            comps[0].path(&["component", "fileID"]).unwrap().as_i64(),
            Some(7)
        );
        assert_eq!(comps[1].path(&["4", "fileID"]).unwrap().as_i64(), Some(8));
        assert_eq!(t.f32_at("field of view"), Some(60.0));
        assert_eq!(t.str_at("m_Name"), Some("My Thing: 2"));
        assert_eq!(t.str_at("empty"), Some(""));
        assert_eq!(t.str_at("guid"), Some("0000000000000000e000000000000000"));
    }

    #[test]
    fn nested_sequences_of_mappings_and_repeated_keys() {
        let body = "Material:\n  m_SavedProperties:\n    m_Floats:\n      data:\n        first:\n          name: _Metallic\n        second: 0.25\n      data:\n        first:\n          name: _Glossiness\n        second: .75\n    m_Colors:\n    - _Color: {r: 1, g: 0.5, b: 0, a: 1}\n    - _EmissionColor: {r: 0, g: 0, b: 0, a: 1}\n  m_Mods:\n    - target: {fileID: 400000, guid: abc, type: 3}\n      propertyPath: m_LocalPosition.x\n      value: 3\n";
        let n = parse(body);
        let m = n.get("Material").unwrap();
        let floats = m.path(&["m_SavedProperties", "m_Floats"]).unwrap();
        let datas: Vec<_> = floats.get_all("data").collect();
        assert_eq!(datas.len(), 2);
        assert_eq!(
            datas[1].path(&["first", "name"]).unwrap().as_str(),
            Some("_Glossiness")
        );
        assert_eq!(datas[1].f32_at("second"), Some(0.75));
        let colors = m.path(&["m_SavedProperties", "m_Colors"]).unwrap().as_seq();
        assert_eq!(colors[0].get("_Color").unwrap().color().unwrap().y, 0.5);
        let mods = m.get("m_Mods").unwrap().as_seq();
        assert_eq!(mods[0].str_at("propertyPath"), Some("m_LocalPosition.x"));
        assert_eq!(mods[0].f32_at("value"), Some(3.0));
        assert_eq!(
            mods[0].path(&["target", "guid"]).unwrap().as_str(),
            Some("abc")
        );
    }

    #[test]
    fn braces_in_names_do_not_swallow_lines() {
        let n = parse("GameObject:\n  m_Name: Door {left\n  m_IsActive: 0\n  m_Component:\n  - component: {fileID: 1,\n      guid: x}\n  m_Layer: 3\n");
        let g = n.get("GameObject").unwrap();
        assert_eq!(g.str_at("m_Name"), Some("Door {left"));
        assert_eq!(g.i64_at("m_IsActive"), Some(0));
        let c = &g.get("m_Component").unwrap().as_seq()[0];
        assert_eq!(
            c.path(&["component", "guid"]).and_then(Node::as_str),
            Some("x")
        );
        assert_eq!(g.i64_at("m_Layer"), Some(3));
    }

    #[test]
    fn absurd_nesting_does_not_overflow_the_stack() {
        let deep = format!("A:\n  k: {}\n", "[".repeat(100_000));
        assert!(parse(&deep).get("A").and_then(|a| a.get("k")).is_some());
        let items = format!("A:\n  k:\n  {}x\n  j: 1\n", "- ".repeat(100_000));
        assert!(parse(&items).get("A").is_some());
        let mut stairs = String::from("A:\n");
        for i in 1..2_000 {
            stairs += &format!("{}k{i}:\n", " ".repeat(i));
        }
        assert!(parse(&stairs).get("A").is_some());
    }

    #[test]
    fn hex_floats_use_the_bits() {
        assert_eq!(parse_f32("0x3fc00000(1.5)"), Some(1.5));
        assert_eq!(parse_f32("0x3f800000(9)"), Some(1.0));
        assert_eq!(parse_f32(".5"), Some(0.5));
        assert_eq!(parse_f32("-.25"), Some(-0.25));
        // Wrapped flow maps, multi-line names and empty values are Unity's own forms.
        let body = "Transform:\n  m_GameObject: {fileID: 12}\n  m_LocalRotation: {x: 0, y: 0.7071068, z: 0,\n    w: 0.7071068}\n  m_Children:\n  - {fileID: 5}\n  m_Component:\n  - component: {fileID: 7}\n  - 4: {fileID: 8}\n  field of view: 60\n  m_Name: My Thing: 2\n  empty:\n";
        assert_eq!(malformed(body), None);
        assert_eq!(
            malformed("GameObject:\n  m_Name: a long\n    name\n  m_Tag: {\n    a: 1}\n"),
            None
        );
    }

    #[test]
    fn stray_closing_brace_in_a_flow_sequence_ends() {
        // Fuzzer find (unity_meta): `[… }` used to loop forever, growing the list.
        let n = parse("A:\n  k: [9cd+6f\0}\n  j: [a, }, b]\n");
        let a = n.get("A").unwrap();
        assert_eq!(a.get("k").unwrap().as_seq().len(), 2);
        let j: Vec<_> = a
            .get("j")
            .unwrap()
            .as_seq()
            .iter()
            .map(|x| x.as_str())
            .collect();
        assert_eq!(j, [Some("a"), Some(""), Some("b")]);
    }

    #[test]
    fn malformed_bodies_name_the_line() {
        let open = "GameObject:\n  m_Component:\n  - component: {fileID: 301\n  m_Name: x\n";
        assert_eq!(
            malformed(open),
            Some((3, "a flow collection opened here is never closed".into()))
        );
        let extra = "Transform:\n  m_LocalPosition: {x: 1, y: 2}}\n";
        assert_eq!(
            malformed(extra).map(|m| m.0),
            Some(2),
            "an extra closing brace"
        );
        let stray = "Transform:\n  m_Father: {fileID: 0}\n  just words here\n";
        let (line, what) = malformed(stray).unwrap();
        assert_eq!(line, 3);
        assert!(what.contains("`just words here`"), "{what}");
    }
}
