//! A prefab instance's `m_Modifications`: a `propertyPath` (`m_LocalPosition.x`,
//! `m_Materials.Array.data[2]`) set to a value or an object reference in one object of
//! the instance. The references the converter follows (`m_Mesh`, `m_Materials`) are
//! edited in the object's typed [`Ref`]s, so they remember the file that wrote them;
//! everything else is set in the body.

use crate::graph::Obj;
use crate::reference::{fref, Ref};
use crate::yaml::Node;

/// Longest `m_Materials` or YAML array a modification may grow.
const MAX_ARRAY: usize = 1 << 16;

/// The `target` fileID of one `m_Modifications` entry.
pub fn target(md: &Node) -> i64 {
    fref(md.get("target")).0
}

/// Apply one `m_Modifications` entry to `obj`; a reference it holds without a GUID was
/// written in file `file`.
pub fn apply(obj: &mut Obj, md: &Node, file: usize) {
    let Some(prop) = md.str_at("propertyPath") else {
        return;
    };
    let value = md.str_at("value").unwrap_or("");
    let objref = md.get("objectReference");
    let (ref_id, _) = fref(objref);
    let new = if value.is_empty() && (ref_id != 0 || is_ref_path(prop)) {
        objref.cloned().unwrap_or(ref_node(0, ""))
    } else {
        Node::Scalar(value.to_string())
    };
    set(obj, prop, new, file);
}

/// Set `prop` of `obj` to `value`; a reference in `value` was written in file `file`.
fn set(obj: &mut Obj, prop: &str, value: Node, file: usize) {
    let segs: Vec<&str> = prop.split('.').collect();
    match segs.split_first() {
        Some((&"m_Mesh", rest)) => set_ref(&mut obj.mesh, rest, &value, file),
        Some((&"m_Materials", rest)) => set_refs(&mut obj.materials, rest, &value, file),
        _ => set_path(&mut obj.body, &segs, value),
    }
}

/// Whether an empty value at `prop` means "no reference" rather than an empty scalar.
fn is_ref_path(prop: &str) -> bool {
    prop == "m_Mesh" || prop.starts_with("m_Materials.Array.data[")
}

/// A reference node as Unity writes one.
fn ref_node(file_id: i64, guid: &str) -> Node {
    Node::Map(vec![
        ("fileID".into(), Node::Scalar(file_id.to_string())),
        ("guid".into(), Node::Scalar(guid.to_string())),
        ("type".into(), Node::Scalar("3".into())),
    ])
}

fn set_ref(r: &mut Ref, rest: &[&str], value: &Node, file: usize) {
    match rest {
        [] => *r = Ref::read(Some(value), file),
        ["fileID"] => r.file_id = value.as_i64().unwrap_or(0),
        ["guid"] => r.guid = value.as_str().filter(|g| !g.is_empty()).map(str::to_string),
        _ => {}
    }
}

fn set_refs(items: &mut Vec<Ref>, rest: &[&str], value: &Node, file: usize) {
    let Some((&first, rest)) = rest.split_first() else {
        *items = Ref::read_all(Some(value), file);
        return;
    };
    if first != "Array" {
        // The list becomes a mapping, which holds no references.
        items.clear();
        return;
    }
    let Some((&what, rest)) = rest.split_first() else {
        return;
    };
    if what == "size" {
        if let Some(n) = array_size(value) {
            items.resize(n, Ref::default());
        }
    } else if let Some(i) = array_index(what) {
        if items.len() <= i {
            items.resize(i + 1, Ref::default());
        }
        set_ref(&mut items[i], rest, value, file);
    }
}

fn array_size(value: &Node) -> Option<usize> {
    value
        .as_i64()
        .filter(|n| (0..MAX_ARRAY as i64).contains(n))
        .map(|n| n as usize)
}

/// `data[i]` → i.
fn array_index(seg: &str) -> Option<usize> {
    seg.strip_prefix("data[")
        .and_then(|s| s.strip_suffix(']'))
        .and_then(|s| s.parse::<usize>().ok())
        .filter(|&i| i < MAX_ARRAY)
}

/// Set a property path in a body, creating mappings and sequences on the way.
fn set_path(node: &mut Node, segs: &[&str], value: Node) {
    let Some((&first, rest)) = segs.split_first() else {
        *node = value;
        return;
    };
    if first == "Array" {
        if !matches!(node, Node::Seq(_)) {
            *node = Node::Seq(vec![]);
        }
        let Node::Seq(items) = node else { return };
        let Some(&what) = rest.first() else { return };
        if what == "size" {
            if let Some(n) = array_size(&value) {
                items.resize(n, ref_node(0, ""));
            }
        } else if let Some(i) = array_index(what) {
            if items.len() <= i {
                items.resize(i + 1, ref_node(0, ""));
            }
            set_path(&mut items[i], &rest[1..], value);
        }
        return;
    }
    if !matches!(node, Node::Map(_)) {
        *node = Node::Map(vec![]);
    }
    let Node::Map(kv) = node else { return };
    let i = match kv.iter().position(|(k, _)| k == first) {
        Some(i) => i,
        None => {
            kv.push((first.to_string(), Node::Scalar(String::new())));
            kv.len() - 1
        }
    };
    set_path(&mut kv[i].1, rest, value);
}
