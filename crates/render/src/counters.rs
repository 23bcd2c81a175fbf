//! Ray counters, one per ray kind. Each tile counts into a plain local struct and adds it
//! to the shared atomics once, so counting costs nothing in the inner loop.

use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RayCounts {
    pub camera: u64,
    pub shadow: u64,
    pub soft_shadow: u64,
    pub reflection: u64,
    /// Hits that camera and reflection rays passed through inside their traversal: faces
    /// their material culls, shadows-only objects (not rays: no query is restarted).
    pub pass_through: u64,
    /// Hits that shadow rays passed through: surfaces that cast no shadow that way.
    pub shadow_pass_through: u64,
    /// Samples whose radiance was NaN or infinite and were replaced by 0 (not a ray kind).
    #[serde(skip)]
    pub sanitized: u64,
}

impl RayCounts {
    pub fn add(&mut self, o: &RayCounts) {
        self.camera += o.camera;
        self.shadow += o.shadow;
        self.soft_shadow += o.soft_shadow;
        self.reflection += o.reflection;
        self.pass_through += o.pass_through;
        self.shadow_pass_through += o.shadow_pass_through;
        self.sanitized += o.sanitized;
    }
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.soft_shadow + self.reflection
    }
}

#[derive(Debug, Default)]
pub struct SharedCounts {
    camera: AtomicU64,
    shadow: AtomicU64,
    soft_shadow: AtomicU64,
    reflection: AtomicU64,
    pass_through: AtomicU64,
    shadow_pass_through: AtomicU64,
    sanitized: AtomicU64,
}

impl SharedCounts {
    pub fn add(&self, c: &RayCounts) {
        self.camera.fetch_add(c.camera, Relaxed);
        self.shadow.fetch_add(c.shadow, Relaxed);
        self.soft_shadow.fetch_add(c.soft_shadow, Relaxed);
        self.reflection.fetch_add(c.reflection, Relaxed);
        self.pass_through.fetch_add(c.pass_through, Relaxed);
        self.shadow_pass_through
            .fetch_add(c.shadow_pass_through, Relaxed);
        self.sanitized.fetch_add(c.sanitized, Relaxed);
    }
    pub fn load(&self) -> RayCounts {
        RayCounts {
            camera: self.camera.load(Relaxed),
            shadow: self.shadow.load(Relaxed),
            soft_shadow: self.soft_shadow.load(Relaxed),
            reflection: self.reflection.load(Relaxed),
            pass_through: self.pass_through.load(Relaxed),
            shadow_pass_through: self.shadow_pass_through.load(Relaxed),
            sanitized: self.sanitized.load(Relaxed),
        }
    }
}
