//! References between Unity objects: `{fileID: n, guid: g, type: t}`. A reference
//! without a GUID names an object of the file it was written in, which is not always
//! the file of the object holding it (a prefab instance's modifications write into the
//! source prefab's objects), so the converter keeps that file beside the ids.

use crate::yaml::Node;

/// A `{fileID: …, guid: …}` reference as read from a body.
pub fn fref(node: Option<&Node>) -> (i64, Option<String>) {
    match node {
        Some(n) => (
            n.i64_at("fileID").unwrap_or(0),
            n.str_at("guid")
                .filter(|g| !g.is_empty())
                .map(str::to_string),
        ),
        None => (0, None),
    }
}

/// A reference and the file it was written in.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ref {
    /// 0 for none.
    pub file_id: i64,
    /// `None` for an object of [`Ref::file`].
    pub guid: Option<String>,
    /// Index into `Graph::files` of the file the reference was written in.
    pub file: usize,
}

impl Ref {
    pub fn read(node: Option<&Node>, file: usize) -> Ref {
        let (file_id, guid) = fref(node);
        Ref {
            file_id,
            guid,
            file,
        }
    }

    /// A reference to an object inside the asset `guid`.
    pub fn asset(file_id: i64, guid: &str) -> Ref {
        Ref {
            file_id,
            guid: Some(guid.to_string()),
            file: 0,
        }
    }

    /// Every reference of a sequence (`m_Materials`).
    pub fn read_all(node: Option<&Node>, file: usize) -> Vec<Ref> {
        node.map(Node::as_seq)
            .unwrap_or(&[])
            .iter()
            .map(|n| Ref::read(Some(n), file))
            .collect()
    }
}
