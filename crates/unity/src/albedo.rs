//! A material's albedo, normal, emission, occlusion and metallic maps in the soup: the textures a `.mat` names,
//! or the file a model's own material names, found the way Unity's model importer finds
//! it. Each image is decoded once per import settings and shared by every material that
//! uses it; a texture that cannot be read leaves the material its tint alone (or without
//! its normal map, or glowing with its emission colour alone), with one warning naming the
//! material and the file.

use crate::emit::Emitter;
use crate::texture::{
    albedo_slot, emission_slot, load, metallic_slot, normal_slot, occlusion_slot, Import,
    TextureSlot,
};
use crate::yaml::Node;
use formats::texture::{TextureRef, Tiling};
use formats::{Material, MetallicMap, NormalMap, OcclusionMap};

/// What a material loses with its albedo map, and with its normal map, as warnings say.
pub(crate) const TINT_ALONE: &str = "drawn with its tint alone";
const NO_NORMAL_MAP: &str = "drawn without its normal map";
const EMISSION_COLOUR_ALONE: &str = "glows with its emission colour alone";
const NO_OCCLUSION_MAP: &str = "drawn without its occlusion map";
const NO_METALLIC_MAP: &str =
    "drawn with its metallic and smoothness values, without its metallic map";
use rayon::prelude::*;
use std::path::{Component, Path, PathBuf};

/// An image a material uses, decoded once the whole scene has been walked.
pub(crate) struct PendingTexture {
    path: PathBuf,
    rel: String,
    import: Import,
    /// The materials that use it, as warnings name them, and what they lose without it.
    users: Vec<(String, &'static str)>,
}

impl Emitter<'_, '_> {
    /// The albedo map of Material `body`; `what` names the material in warnings.
    pub(crate) fn mat_albedo(&mut self, body: &Node, what: &str) -> Option<TextureRef> {
        self.albedo(&albedo_slot(body)?, what)
    }

    /// The albedo map `slot` names; `what` names its material in warnings.
    pub(crate) fn albedo(&mut self, slot: &TextureSlot, what: &str) -> Option<TextureRef> {
        self.slot_texture(slot, what, TINT_ALONE)
    }

    /// The texture `slot` names, imported as its `.meta` says, or None with one warning
    /// naming the material (`what`) and what it is drawn `without`.
    fn slot_texture(
        &mut self,
        slot: &TextureSlot,
        what: &str,
        without: &'static str,
    ) -> Option<TextureRef> {
        let path = self.slot_file(slot, what, without)?;
        self.texture_ref(&path, Import::read(&path), slot.tiling, what, without)
    }

    /// The file slot `slot` names, or None with one warning naming the material (`what`),
    /// the slot, and what the material is drawn `without`.
    fn slot_file(&mut self, slot: &TextureSlot, what: &str, without: &str) -> Option<PathBuf> {
        let path = self.g.project.resolve(&slot.guid).cloned();
        if path.is_none() {
            self.soup.warnings.push(format!(
                "{what}: {}: texture GUID {} is not in the project; {without}",
                slot.property, slot.guid
            ));
        }
        path
    }

    /// The emission map of Material `body` where it can show: the material glows
    /// (`emission`, the converted emission colour, is not black).
    pub(crate) fn mat_emission(
        &mut self,
        body: &Node,
        emission: glam::Vec3,
        what: &str,
    ) -> Option<TextureRef> {
        if emission.max_element() <= 0.0 {
            return None;
        }
        self.slot_texture(&emission_slot(body)?, what, EMISSION_COLOUR_ALONE)
    }

    /// The occlusion map of Material `body` where its shader samples one with a strength
    /// above 0; `what` names the material in warnings.
    pub(crate) fn mat_occlusion(&mut self, body: &Node, what: &str) -> Option<OcclusionMap> {
        let (slot, strength) = occlusion_slot(body)?;
        if strength <= 0.0 {
            return None;
        }
        let map = self.slot_texture(&slot, what, NO_OCCLUSION_MAP)?;
        Some(OcclusionMap { map, strength })
    }

    /// The metallic map of Material `body` where its shader samples one; `what` names the
    /// material in warnings. The texture is read as imported: Unity decodes an sRGB one
    /// before the shader reads its red channel.
    pub(crate) fn mat_metallic(&mut self, body: &Node, what: &str) -> Option<MetallicMap> {
        let (slot, smoothness) = metallic_slot(body)?;
        let map = self.slot_texture(&slot, what, NO_METALLIC_MAP)?;
        Some(MetallicMap { map, smoothness })
    }

    /// The normal map of Material `body` where its shader samples one; `what` names the
    /// material in warnings. Unity imports a normal map as linear data whatever the sRGB
    /// box says.
    pub(crate) fn mat_normal(&mut self, body: &Node, what: &str) -> Option<NormalMap> {
        let (slot, scale) = normal_slot(body)?;
        let path = self.slot_file(&slot, what, NO_NORMAL_MAP)?;
        let import = Import {
            srgb: false,
            ..Import::read(&path)
        };
        if import.from_grayscale {
            self.soup.warnings.push(format!(
                "{what}: {}: {} is a height map Unity turns into normals on import \
                 (Create from Grayscale), which is not supported; {NO_NORMAL_MAP}",
                slot.property,
                self.g.project.rel(&path)
            ));
            return None;
        }
        let map = self.texture_ref(&path, import, slot.tiling, what, NO_NORMAL_MAP)?;
        Some(NormalMap { map, scale })
    }

    /// The soup texture of the image at `path` with `tiling`. The image is only named
    /// here; [`Emitter::decode_textures`] decodes every named image at the end, all at once
    /// on every core (decoding dominates converting a textured scene).
    pub(crate) fn texture_ref(
        &mut self,
        path: &Path,
        import: Import,
        tiling: Tiling,
        what: &str,
        without: &'static str,
    ) -> Option<TextureRef> {
        // The same image imported twice with different settings is two textures to Unity.
        let key = format!("{}\n{import:?}", path.display());
        let texture = match self.textures.get(&key) {
            Some(&i) => i,
            None => {
                let i = self.pending_textures.len() as u32;
                self.pending_textures.push(PendingTexture {
                    path: path.to_path_buf(),
                    rel: self.g.project.rel(path),
                    import,
                    users: Vec::new(),
                });
                self.textures.insert(key, i);
                i
            }
        };
        self.pending_textures[texture as usize]
            .users
            .push((what.to_string(), without));
        Some(TextureRef { texture, tiling })
    }

    /// Decode every texture [`Emitter::texture_ref`] named, in parallel, into the soup. A
    /// texture that cannot be read is dropped from the materials that use it, with one
    /// warning per material; UVs go too when no texture is left.
    pub(crate) fn decode_textures(&mut self) {
        let pending = std::mem::take(&mut self.pending_textures);
        let decoded: Vec<_> = pending
            .par_iter()
            .map(|p| load(&p.path, &p.rel, &p.import))
            .collect();
        let mut index = Vec::with_capacity(decoded.len());
        for (p, d) in pending.iter().zip(decoded) {
            match d {
                Ok(t) => {
                    index.push(Some(self.soup.textures.len() as u32));
                    self.soup.textures.push(t);
                }
                Err(e) => {
                    index.push(None);
                    for (what, without) in &p.users {
                        self.soup.warnings.push(format!("{what}: {e}; {without}"));
                    }
                }
            }
        }
        let decoded =
            |r: TextureRef| index[r.texture as usize].map(|texture| TextureRef { texture, ..r });
        for m in &mut self.soup.materials {
            m.albedo_map = m.albedo_map.and_then(decoded);
            m.normal_map = m
                .normal_map
                .and_then(|n| decoded(n.map).map(|map| NormalMap { map, ..n }));
            m.emission_map = m.emission_map.and_then(decoded);
            m.occlusion_map = m
                .occlusion_map
                .and_then(|o| decoded(o.map).map(|map| OcclusionMap { map, ..o }));
            m.metallic_map = m
                .metallic_map
                .and_then(|g| decoded(g.map).map(|map| MetallicMap { map, ..g }));
        }
        if !self.soup.materials.iter().any(Material::reads_uvs) {
            self.soup.uvs = Vec::new();
        }
    }

    /// The file Unity's model importer binds to the texture a model's material names
    /// (`written`, as the model file spells it, often an absolute path on the author's
    /// machine): that path relative to the model, then the file name next to the model,
    /// in a `Textures/` folder beside it or beside any folder above it inside Assets, and
    /// last anywhere in Assets by name.
    pub(crate) fn model_texture(&mut self, model: &Path, written: &str) -> Option<PathBuf> {
        let key = (model.to_path_buf(), written.to_string());
        if let Some(found) = self.model_textures.get(&key) {
            return found.clone();
        }
        let found = self.find_model_texture(model, written);
        self.model_textures.insert(key, found.clone());
        found
    }

    fn find_model_texture(&self, model: &Path, written: &str) -> Option<PathBuf> {
        let project = self.g.project;
        let dir = model.parent()?;
        let relative = written.replace('\\', "/");
        if !relative.starts_with('/') && !relative.contains(':') {
            // Folded lexically, so the file has one name however a model spells its way
            // there (textures are shared by path).
            let p = fold(&dir.join(&relative));
            if p.is_file() && p.starts_with(&project.assets) {
                return Some(p);
            }
        }
        let name = relative.rsplit('/').next().filter(|n| !n.is_empty())?;
        if let Some(p) = crate::material::file_in(dir, name) {
            return Some(p);
        }
        let mut d = dir.to_path_buf();
        loop {
            if let Some(p) = crate::material::file_in(&d.join("Textures"), name) {
                return Some(p);
            }
            if d == project.assets || !d.pop() || !d.starts_with(&project.assets) {
                break;
            }
        }
        project.find_by_name(name).cloned()
    }
}

/// `path` without `.` and `..` components (a `..` drops the component before it).
fn fold(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_removes_dot_components() {
        assert_eq!(
            fold(Path::new("/p/Assets/Models/./../Textures/a.png")),
            PathBuf::from("/p/Assets/Textures/a.png")
        );
    }
}
