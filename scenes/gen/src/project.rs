//! A Unity project held in memory (path → bytes), so the same files can be written to
//! disk or compared with the committed ones.

use crate::{ids, meta};
use std::collections::{BTreeMap, BTreeSet};
use std::io;
use std::path::Path;

/// The editor version the bundled projects claim, with its changeset.
const PROJECT_VERSION: &str =
    "m_EditorVersion: 2022.3.20f1\nm_EditorVersionWithRevision: 2022.3.20f1 (61c2feb0970d)\n";

/// The bundled projects' lights are authored in linear units: intensity times the linear
/// colour, with colour temperature available (Unity fills in every other setting).
const GRAPHICS_SETTINGS: &str = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!30 &1\nGraphicsSettings:\n  m_ObjectHideFlags: 0\n  m_LightsUseLinearIntensity: 1\n  m_LightsUseColorTemperature: 1\n";

pub struct Project {
    /// Folder name under `scenes/`.
    pub name: String,
    /// Relative path (with `/`) → content.
    pub files: BTreeMap<String, Vec<u8>>,
}

impl Project {
    pub fn new(name: &str) -> Self {
        let mut p = Project {
            name: name.to_string(),
            files: BTreeMap::new(),
        };
        p.add("ProjectSettings/ProjectVersion.txt", PROJECT_VERSION);
        p.add("ProjectSettings/GraphicsSettings.asset", GRAPHICS_SETTINGS);
        p
    }

    pub fn guid(&self, asset_path: &str) -> String {
        ids::guid(&self.name, asset_path)
    }

    pub fn add(&mut self, path: &str, text: impl Into<String>) {
        self.files
            .insert(path.to_string(), text.into().into_bytes());
    }

    /// Add an asset and its `.meta` (made by `meta_of` from the asset's GUID); returns the GUID.
    pub fn add_asset(
        &mut self,
        path: &str,
        text: impl Into<String>,
        meta_of: fn(&str) -> String,
    ) -> String {
        self.add_binary_asset(path, text.into().into_bytes(), meta_of)
    }

    /// [`Project::add_asset`] for a file that is not text (a binary FBX model).
    pub fn add_binary_asset(
        &mut self,
        path: &str,
        bytes: Vec<u8>,
        meta_of: fn(&str) -> String,
    ) -> String {
        let guid = self.guid(path);
        self.files.insert(path.to_string(), bytes);
        self.add(&format!("{path}.meta"), meta_of(&guid));
        guid
    }

    /// Give every folder under `Assets/` its `.meta`, as the editor does on import.
    pub fn finish(mut self) -> Self {
        let mut folders = BTreeSet::new();
        for path in self.files.keys() {
            let mut p = Path::new(path).parent();
            while let Some(dir) = p {
                let d = dir.to_string_lossy().to_string();
                if d.starts_with("Assets/") {
                    folders.insert(d);
                }
                p = dir.parent();
            }
        }
        for d in folders {
            let guid = self.guid(&d);
            self.add(&format!("{d}.meta"), meta::folder(&guid));
        }
        self
    }

    /// Write every file under `root/<name>/` atomically, and delete files there that the
    /// generator no longer makes (so regenerating converges). Returns the deleted paths.
    pub fn write(&self, root: &Path) -> io::Result<Vec<String>> {
        let dir = root.join(&self.name);
        for (rel, bytes) in &self.files {
            let path = dir.join(rel);
            if std::fs::read(&path).ok().as_deref() == Some(bytes.as_slice()) {
                continue;
            }
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)?;
            }
            formats::write_atomic(&path, bytes).map_err(io::Error::other)?;
        }
        let mut stale = Vec::new();
        for rel in existing_files(&dir)? {
            if !self.files.contains_key(&rel) {
                std::fs::remove_file(dir.join(&rel))?;
                stale.push(rel);
            }
        }
        Ok(stale)
    }
}

/// Every file under `dir`, as `/`-separated relative paths (empty when `dir` is absent).
pub fn existing_files(dir: &Path) -> io::Result<BTreeSet<String>> {
    let mut out = BTreeSet::new();
    if !dir.exists() {
        return Ok(out);
    }
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d)? {
            let entry = entry?;
            let path = entry.path();
            if entry.file_type()?.is_dir() {
                stack.push(path);
            } else if let Ok(rel) = path.strip_prefix(dir) {
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().to_string())
                    .collect();
                out.insert(parts.join("/"));
            }
        }
    }
    Ok(out)
}
