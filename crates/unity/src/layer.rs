//! Layers and culling masks: a GameObject's `m_Layer`, and the `m_CullingMask` of cameras
//! (which layers they draw) and lights (which layers they light).

use crate::emit::Emitter;
use crate::yaml::Node;

/// Every layer: what Unity writes for "Everything", and the mask when none is given.
pub const EVERYTHING: u32 = u32::MAX;

/// A camera's or light's `m_CullingMask.m_Bits` (older files write -1 for Everything).
pub fn culling_mask(body: &Node) -> u32 {
    body.path(&["m_CullingMask", "m_Bits"])
        .and_then(Node::as_i64)
        .map_or(EVERYTHING, |bits| bits as u32)
}

/// A GameObject's `m_Layer`; Unity has 32 layers, anything else reads as Default (0).
pub fn layer(go_body: &Node) -> u8 {
    go_body
        .i64_at("m_Layer")
        .filter(|l| (0..32).contains(l))
        .map_or(0, |l| l as u8)
}

impl Emitter<'_, '_> {
    /// Whether the chosen camera draws GameObject `go`; when not, says why in `skipped`.
    pub(crate) fn camera_draws(&mut self, go: usize) -> bool {
        let l = layer(&self.g.objs[go].body);
        if self.camera_mask >> l & 1 == 1 {
            return true;
        }
        let line = format!(
            "object {:?}: layer {l} is outside camera {:?}'s culling mask; not converted",
            self.path(go),
            self.soup.camera.name
        );
        self.skipped.push(line);
        false
    }
}
