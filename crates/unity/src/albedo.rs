//! A material's albedo map in the soup: the texture a `.mat` names, or the file a model's
//! own material names, found the way Unity's model importer finds it. Each image is
//! decoded once per import settings and shared by every material that uses it; a texture
//! that cannot be read leaves the material its tint alone, with one warning naming the
//! material and the file.

use crate::emit::Emitter;
use crate::texture::{albedo_slot, load, Import};
use crate::yaml::Node;
use formats::texture::{TextureRef, Tiling};
use std::path::{Component, Path, PathBuf};

impl Emitter<'_, '_> {
    /// The albedo map of Material `body`; `what` names the material in warnings.
    pub(crate) fn mat_albedo(&mut self, body: &Node, what: &str) -> Option<TextureRef> {
        let slot = albedo_slot(body)?;
        let Some(path) = self.g.project.resolve(&slot.guid).cloned() else {
            self.soup.warnings.push(format!(
                "{what}: {}: texture GUID {} is not in the project; drawn with its tint alone",
                slot.property, slot.guid
            ));
            return None;
        };
        self.texture_ref(&path, slot.tiling, what)
    }

    /// The soup texture of the image at `path` with `tiling`, decoded on first use.
    pub(crate) fn texture_ref(
        &mut self,
        path: &Path,
        tiling: Tiling,
        what: &str,
    ) -> Option<TextureRef> {
        let import = Import::read(path);
        // The same image imported twice with different settings is two textures to Unity.
        let key = format!("{}\n{import:?}", path.display());
        let got = match self.textures.get(&key) {
            Some(r) => r.clone(),
            None => {
                let rel = self.g.project.rel(path);
                let r = load(path, &rel, &import)
                    .map(|t| {
                        self.soup.textures.push(t);
                        (self.soup.textures.len() - 1) as u32
                    })
                    .map_err(|e| e.to_string());
                self.textures.insert(key, r.clone());
                r
            }
        };
        match got {
            Ok(texture) => Some(TextureRef { texture, tiling }),
            Err(e) => {
                self.soup
                    .warnings
                    .push(format!("{what}: {e}; drawn with its tint alone"));
                None
            }
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
