//! LODGroup (class 205): the editor's camera up close shows LOD0, so only LOD0's renderers
//! are drawn; drawing every level would show the object several times over.

use crate::docs;
use crate::emit::{enabled, Emitter};
use crate::reference::fref;
use std::collections::{HashMap, HashSet};

impl Emitter<'_, '_> {
    /// Renderers (arena indices) that only levels above LOD0 of an enabled LODGroup on an
    /// active GameObject list, each with the level and group that hide it.
    pub(crate) fn lod_hidden(&self) -> HashMap<usize, String> {
        let g = self.g;
        // `renderer: {fileID: N}` names a renderer of the group's own file.
        let mut by_id: HashMap<(usize, i64), Vec<usize>> = HashMap::new();
        for (i, o) in g.objs.iter().enumerate() {
            if matches!(o.class, docs::MESH_RENDERER | docs::SKINNED_MESH_RENDERER) {
                by_id.entry((o.file, o.file_id)).or_default().push(i);
            }
        }
        let mut hidden = HashMap::new();
        for o in &g.objs {
            if o.class != docs::LOD_GROUP || o.removed || !enabled(o) {
                continue;
            }
            if !o.go.is_some_and(|go| self.active(go)) {
                continue;
            }
            let group = o.go.map(|go| self.path(go)).unwrap_or_default();
            let levels: Vec<Vec<usize>> = o
                .body
                .get("m_LODs")
                .map(|l| l.as_seq())
                .unwrap_or_default()
                .iter()
                .map(|level| {
                    level
                        .get("renderers")
                        .map(|r| r.as_seq())
                        .unwrap_or_default()
                        .iter()
                        .flat_map(|r| {
                            let (id, _) = fref(r.get("renderer"));
                            by_id.get(&(o.file, id)).cloned().unwrap_or_default()
                        })
                        .collect()
                })
                .collect();
            let Some((lod0, rest)) = levels.split_first() else {
                continue;
            };
            let shown: HashSet<usize> = lod0.iter().copied().collect();
            for (k, level) in rest.iter().enumerate() {
                for &r in level.iter().filter(|r| !shown.contains(r)) {
                    hidden
                        .entry(r)
                        .or_insert_with(|| format!("LOD{} of LODGroup {group:?}", k + 1));
                }
            }
        }
        hidden
    }
}
