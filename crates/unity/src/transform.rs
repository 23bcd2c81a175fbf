//! Transforms and the hierarchy (classes 1, 4 and 224): local and world matrices,
//! hierarchy paths for names and messages, and whether a GameObject is active in the
//! hierarchy.

use crate::emit::{EmitError, Emitter};
use crate::yaml::Node;
use glam::{Mat4, Quat, Vec3};

/// Deepest hierarchy walked; deeper chains are treated as ending there.
const MAX_DEPTH: usize = 256;

/// A Transform body's local matrix (T·R·S); a zero rotation counts as none.
pub fn local(b: &Node) -> Mat4 {
    let pos = b
        .get("m_LocalPosition")
        .and_then(Node::vec3)
        .unwrap_or(Vec3::ZERO);
    let rot = b
        .get("m_LocalRotation")
        .and_then(Node::quat)
        .unwrap_or(Quat::IDENTITY);
    let scale = b
        .get("m_LocalScale")
        .and_then(Node::vec3)
        .unwrap_or(Vec3::ONE);
    let rot = if rot.length_squared() > 0.0 {
        rot.normalize()
    } else {
        Quat::IDENTITY
    };
    Mat4::from_translation(pos) * Mat4::from_quat(rot) * Mat4::from_scale(scale)
}

impl Emitter<'_, '_> {
    pub(crate) fn name(&self, go: usize) -> String {
        self.g.objs[go]
            .body
            .str_at("m_Name")
            .unwrap_or("")
            .to_string()
    }

    /// Hierarchy path of a GameObject, segments joined by '/'.
    pub(crate) fn path(&self, go: usize) -> String {
        let mut parts = vec![self.name(go)];
        let mut tf = self.go_tf.get(&go).copied();
        let mut guard = 0;
        while let Some(t) = tf.and_then(|t| self.g.objs[t].father) {
            guard += 1;
            if guard > MAX_DEPTH {
                break;
            }
            if let Some(pg) = self.g.objs[t].go {
                parts.push(self.name(pg));
            }
            tf = Some(t);
        }
        parts.reverse();
        parts.join("/")
    }

    /// "scene: object 'path' (fileID n)" for messages.
    pub(crate) fn describe(&self, go: usize) -> String {
        format!(
            "{}: object '{}' (fileID {})",
            self.scene_rel,
            self.path(go),
            self.g.objs[go].file_id
        )
    }

    /// Active in the hierarchy: itself and every ancestor active and not removed.
    pub(crate) fn active(&self, go: usize) -> bool {
        let mut cur = Some(go);
        let mut guard = 0;
        while let Some(g) = cur {
            guard += 1;
            let o = &self.g.objs[g];
            if guard > MAX_DEPTH || o.removed || o.body.i64_at("m_IsActive") == Some(0) {
                return false;
            }
            cur = self
                .go_tf
                .get(&g)
                .and_then(|&t| self.g.objs[t].father)
                .and_then(|f| self.g.objs[f].go);
        }
        true
    }

    /// Local-to-world of a Transform as a full matrix (parent·T·R·S).
    pub(crate) fn world(&mut self, t: usize) -> Mat4 {
        if let Some(m) = self.world.get(&t) {
            return *m;
        }
        let mut chain = vec![t];
        let mut cur = self.g.objs[t].father;
        while let Some(f) = cur {
            if self.world.contains_key(&f) || chain.contains(&f) || chain.len() > MAX_DEPTH {
                break;
            }
            chain.push(f);
            cur = self.g.objs[f].father;
        }
        let mut m = cur
            .and_then(|f| self.world.get(&f).copied())
            .unwrap_or(Mat4::IDENTITY);
        for &n in chain.iter().rev() {
            if self.g.objs[n].on_terrain {
                m = Mat4::from_translation(m.w_axis.truncate());
            }
            m *= local(&self.g.objs[n].body);
            self.world.insert(n, m);
        }
        m
    }

    /// A GameObject's local-to-world, refused when it is not finite.
    pub(crate) fn checked_world(&mut self, go: usize) -> Result<Mat4, EmitError> {
        let m = match self.go_tf.get(&go).copied() {
            Some(t) => self.world(t),
            None => Mat4::IDENTITY,
        };
        if m.is_finite() {
            Ok(m)
        } else {
            Err(self.non_finite(go, "transform has a NaN or infinite value".into()))
        }
    }

    pub(crate) fn non_finite(&self, go: usize, detail: String) -> EmitError {
        EmitError::NonFinite {
            file: self.scene_rel.to_string(),
            object: self.path(go),
            file_id: self.g.objs[go].file_id,
            detail,
        }
    }
}
