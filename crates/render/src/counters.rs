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
    /// their material culls, shadows-only objects, cut-out holes (not rays: no query is
    /// restarted).
    pub pass_through: u64,
    /// Hits that shadow rays passed through: surfaces that cast no shadow that way and
    /// cut-out holes.
    pub shadow_pass_through: u64,
    /// Camera and reflection rays continued past a blended (Transparent/Fade) surface for
    /// the light behind it: each a query from the hit onwards.
    pub blend_continuation: u64,
    /// Blended surfaces that attenuated a shadow ray (each triangle once per ray).
    pub shadow_blend: u64,
    /// Soft-shadow samples (counted in `soft_shadow`) found blocked by the opaque caster
    /// that blocked an earlier sample of the same point: one triangle test, no walk.
    pub shadow_reuse: u64,
    /// Soft shadows decided by their four rim probes (counted in `soft_shadow`), which
    /// let the same share of the light through, so that no sample was traced.
    pub soft_decided: u64,
    /// Albedo lookups at shaded points.
    pub texture_lookups: u64,
    /// Normal-map lookups at shaded points.
    pub normal_lookups: u64,
    /// Emission-map lookups at shaded points of glowing materials.
    pub emission_lookups: u64,
    /// Occlusion map texels read.
    pub occlusion_lookups: u64,
    /// Metallic map texels read.
    pub metallic_lookups: u64,
    /// Reflection probe lookups: the skybox reflected by a physically based surface.
    pub probe_lookups: u64,
    /// Alpha lookups: cut-out tests inside the traversals and blended surfaces' alpha where
    /// no albedo lookup gave it.
    pub alpha_lookups: u64,
    /// Surface hits mixed toward the fog colour (camera, reflection and continued rays).
    pub fogged: u64,
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
        self.blend_continuation += o.blend_continuation;
        self.shadow_blend += o.shadow_blend;
        self.shadow_reuse += o.shadow_reuse;
        self.soft_decided += o.soft_decided;
        self.texture_lookups += o.texture_lookups;
        self.normal_lookups += o.normal_lookups;
        self.emission_lookups += o.emission_lookups;
        self.occlusion_lookups += o.occlusion_lookups;
        self.metallic_lookups += o.metallic_lookups;
        self.probe_lookups += o.probe_lookups;
        self.alpha_lookups += o.alpha_lookups;
        self.fogged += o.fogged;
        self.sanitized += o.sanitized;
    }
    /// Queries traced: every ray kind, blend continuations included.
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.soft_shadow + self.reflection + self.blend_continuation
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
    blend_continuation: AtomicU64,
    shadow_blend: AtomicU64,
    shadow_reuse: AtomicU64,
    soft_decided: AtomicU64,
    texture_lookups: AtomicU64,
    normal_lookups: AtomicU64,
    emission_lookups: AtomicU64,
    occlusion_lookups: AtomicU64,
    metallic_lookups: AtomicU64,
    probe_lookups: AtomicU64,
    alpha_lookups: AtomicU64,
    fogged: AtomicU64,
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
        self.blend_continuation
            .fetch_add(c.blend_continuation, Relaxed);
        self.shadow_blend.fetch_add(c.shadow_blend, Relaxed);
        self.shadow_reuse.fetch_add(c.shadow_reuse, Relaxed);
        self.soft_decided.fetch_add(c.soft_decided, Relaxed);
        self.texture_lookups.fetch_add(c.texture_lookups, Relaxed);
        self.normal_lookups.fetch_add(c.normal_lookups, Relaxed);
        self.emission_lookups.fetch_add(c.emission_lookups, Relaxed);
        self.occlusion_lookups
            .fetch_add(c.occlusion_lookups, Relaxed);
        self.metallic_lookups.fetch_add(c.metallic_lookups, Relaxed);
        self.probe_lookups.fetch_add(c.probe_lookups, Relaxed);
        self.alpha_lookups.fetch_add(c.alpha_lookups, Relaxed);
        self.fogged.fetch_add(c.fogged, Relaxed);
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
            blend_continuation: self.blend_continuation.load(Relaxed),
            shadow_blend: self.shadow_blend.load(Relaxed),
            shadow_reuse: self.shadow_reuse.load(Relaxed),
            soft_decided: self.soft_decided.load(Relaxed),
            texture_lookups: self.texture_lookups.load(Relaxed),
            normal_lookups: self.normal_lookups.load(Relaxed),
            emission_lookups: self.emission_lookups.load(Relaxed),
            occlusion_lookups: self.occlusion_lookups.load(Relaxed),
            metallic_lookups: self.metallic_lookups.load(Relaxed),
            probe_lookups: self.probe_lookups.load(Relaxed),
            alpha_lookups: self.alpha_lookups.load(Relaxed),
            fogged: self.fogged.load(Relaxed),
            sanitized: self.sanitized.load(Relaxed),
        }
    }
}
