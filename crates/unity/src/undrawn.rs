//! Components that draw in Unity's view but not in unitrace's: sprites, 3D text, lines
//! and particles. None is converted; each kind enabled on a layer the camera draws is
//! named once, with how many there are and the first few objects, so that a picture
//! without them does not come as a surprise.

use crate::docs;
use crate::emit::{enabled, Emitter};
use crate::layer::layer;

/// The kinds said: the class of the component that decides whether one is drawn, its
/// name, plural, and why it is missing.
const KINDS: [(u32, &str, &str, &str); 5] = [
    (
        docs::SPRITE_RENDERER,
        "SpriteRenderer",
        "SpriteRenderers",
        "sprites are not converted",
    ),
    // A TextMesh is drawn by the MeshRenderer beside it, which has no MeshFilter.
    (
        docs::TEXT_MESH,
        "TextMesh",
        "TextMeshes",
        "3D text is not converted",
    ),
    (
        docs::LINE_RENDERER,
        "LineRenderer",
        "LineRenderers",
        "lines are not converted",
    ),
    (
        docs::PARTICLE_SYSTEM_RENDERER,
        "ParticleSystem",
        "ParticleSystems",
        "particles are not simulated",
    ),
    (
        docs::TILEMAP_RENDERER,
        "TilemapRenderer",
        "TilemapRenderers",
        "tilemaps are not converted",
    ),
];

/// How many objects each warning names before it counts the rest.
const NAMED: usize = 3;

/// Per kind, the objects seen so far.
#[derive(Default)]
pub(crate) struct Undrawn {
    found: [Vec<String>; KINDS.len()],
}

impl Emitter<'_, '_> {
    /// Notes GameObject `go` (active) for each kind among its components that Unity
    /// would draw: enabled (for a TextMesh, its MeshRenderer), on a layer the camera draws.
    pub(crate) fn note_undrawn(&self, go: usize, comps: &[usize], undrawn: &mut Undrawn) {
        let objs = &self.g.objs;
        if self.camera_mask >> layer(&objs[go].body) & 1 == 0 {
            return;
        }
        let renderer_on = |class: u32| {
            comps
                .iter()
                .any(|&c| objs[c].class == class && enabled(&objs[c]))
        };
        for (k, &(class, ..)) in KINDS.iter().enumerate() {
            let drawn = match class {
                docs::TEXT_MESH => {
                    comps.iter().any(|&c| objs[c].class == class)
                        && renderer_on(docs::MESH_RENDERER)
                }
                _ => renderer_on(class),
            };
            if drawn {
                undrawn.found[k].push(self.path(go));
            }
        }
    }

    /// One warning per kind found.
    pub(crate) fn warn_undrawn(&mut self, undrawn: Undrawn) {
        for ((_, name, plural, why), objects) in KINDS.iter().zip(undrawn.found) {
            let Some(first) = objects.first() else {
                continue;
            };
            let line = if objects.len() == 1 {
                format!(
                    "{}: object '{first}': {name} not drawn: {why}",
                    self.scene_rel
                )
            } else {
                let shown: Vec<String> = objects
                    .iter()
                    .take(NAMED)
                    .map(|o| format!("'{o}'"))
                    .collect();
                let more = match objects.len().saturating_sub(NAMED) {
                    0 => String::new(),
                    n => format!(" and {n} more"),
                };
                format!(
                    "{}: {} {plural} not drawn ({}{more}): {why}",
                    self.scene_rel,
                    objects.len(),
                    shown.join(", ")
                )
            };
            self.soup.warnings.push(line);
        }
    }
}
