//! Splitting a Unity YAML file (scene or prefab) into its documents.
//!
//! Every object is a document headed `--- !u!<classID> &<fileID>` with an optional
//! ` stripped`. Only the header is read here; bodies are parsed on demand, each alone,
//! so one odd document cannot sink the file.

use crate::yaml::{self, Node};

pub const GAME_OBJECT: u32 = 1;
pub const TRANSFORM: u32 = 4;
pub const CAMERA: u32 = 20;
pub const MATERIAL: u32 = 21;
pub const MESH_RENDERER: u32 = 23;
pub const GRAPHICS_SETTINGS: u32 = 30;
pub const MESH_FILTER: u32 = 33;
pub const MESH: u32 = 43;
pub const QUALITY_SETTINGS: u32 = 47;
pub const RENDER_SETTINGS: u32 = 104;
pub const LIGHT: u32 = 108;
pub const TEXT_MESH: u32 = 102;
pub const MONO_BEHAVIOUR: u32 = 114;
pub const LINE_RENDERER: u32 = 120;
pub const PLAYER_SETTINGS: u32 = 129;
pub const SKINNED_MESH_RENDERER: u32 = 137;
pub const PARTICLE_SYSTEM_RENDERER: u32 = 199;
pub const LOD_GROUP: u32 = 205;
pub const SPRITE_RENDERER: u32 = 212;
pub const TERRAIN: u32 = 218;
pub const RECT_TRANSFORM: u32 = 224;
pub const PREFAB_INSTANCE: u32 = 1001;
pub const TILEMAP_RENDERER: u32 = 483693784;
pub const TERRAIN_LAYER: u32 = 1953259897;

pub struct Doc<'a> {
    pub class: u32,
    pub file_id: i64,
    pub stripped: bool,
    /// The body, starting with the `ClassName:` line.
    pub body: &'a str,
}

impl Doc<'_> {
    /// The parsed body's inner mapping (under the `ClassName:` key).
    pub fn parse(&self) -> Node {
        match yaml::parse(self.body) {
            Node::Map(mut kv) if !kv.is_empty() => kv.swap_remove(0).1,
            other => other,
        }
    }
}

/// Parse a header line `--- !u!<class> &<fileID>[ stripped]`.
fn header(line: &str) -> Option<(u32, i64, bool)> {
    let rest = line.strip_prefix("--- !u!")?;
    let (class, rest) = rest.split_once(" &")?;
    let class = class.parse().ok()?;
    let rest = rest.trim_end();
    let (id, stripped) = match rest.strip_suffix(" stripped") {
        Some(id) => (id, true),
        None => (rest, false),
    };
    Some((class, id.parse().ok()?, stripped))
}

/// True when the bytes look like a text (YAML) Unity file.
pub fn is_text_yaml(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(64)];
    let head = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
    head.starts_with(b"%YAML") || head.starts_with(b"--- !u!")
}

/// Whether the text holds a document, as [`split`] finds them, without splitting it all.
pub fn has_document(text: &str) -> bool {
    text.lines()
        .any(|l| l.starts_with("--- !u!") && header(l.trim_end()).is_some())
}

/// The first document of `class` in `text`, parsed.
pub fn first(text: &str, class: u32) -> Option<Node> {
    split(text)
        .into_iter()
        .find(|d| d.class == class)
        .map(|d| d.parse())
}

/// All documents of a text file, in file order.
pub fn split(text: &str) -> Vec<Doc<'_>> {
    let mut docs = Vec::new();
    let mut current: Option<(u32, i64, bool, usize)> = None;
    let mut offset = 0usize;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        if line.starts_with("--- !u!") {
            if let Some(h) = header(line.trim_end()) {
                if let Some((class, file_id, stripped, body)) = current.take() {
                    docs.push(Doc {
                        class,
                        file_id,
                        stripped,
                        body: &text[body..start],
                    });
                }
                current = Some((h.0, h.1, h.2, offset));
            }
        }
    }
    if let Some((class, file_id, stripped, body)) = current {
        docs.push(Doc {
            class,
            file_id,
            stripped,
            body: &text[body..],
        });
    }
    docs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_headers_with_negative_ids_and_stripped() {
        let text = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!1 &-42\nGameObject:\n  m_Name: a\n--- !u!4 &9223372036854775807 stripped\nTransform:\n  m_PrefabInstance: {fileID: 3}\n";
        let d = split(text);
        assert_eq!(d.len(), 2);
        assert_eq!((d[0].class, d[0].file_id, d[0].stripped), (1, -42, false));
        assert_eq!(d[0].parse().str_at("m_Name"), Some("a"));
        assert_eq!(
            (d[1].class, d[1].file_id, d[1].stripped),
            (4, i64::MAX, true)
        );
        assert!(is_text_yaml(text.as_bytes()));
        assert!(!is_text_yaml(&[0, 0, 0x2e, 0x4b, 0, 0]));
    }
}
