//! What a benchmark run measures: inputs, ray counts, repetitions, thread counts.

use formats::BuildParams;
use std::path::PathBuf;

#[derive(Clone, Debug)]
pub struct Config {
    /// A soup written by `unity2soup` (skipped with a message when absent).
    pub baseline: Option<PathBuf>,
    /// A folder of OBJ meshes (skipped loudly when absent).
    pub meshes: Option<PathBuf>,
    /// Triangles in the generated scene (0: none).
    pub generated: usize,
    /// Primary rays: an `image` × `image` camera.
    pub image: u32,
    pub random_rays: usize,
    /// Rays per packet query in the packet columns: 4, 8 or 16 (the k-d tree traces a
    /// packet of 8 or 16 as two or four of 4; Embree with `rtcIntersect8` / `16`).
    pub packet: usize,
    /// Timed runs per measurement (the median is reported).
    pub runs: usize,
    /// Thread counts to measure (rayon pool sizes, and Embree build threads).
    pub threads: Vec<usize>,
    /// Brute force runs only on scenes with at most this many triangles …
    pub brute_max_triangles: usize,
    /// … and on this many rays of each set.
    pub brute_rays: usize,
    pub params: BuildParams,
    #[cfg(feature = "embree")]
    pub embree_quality: crate::embree::Quality,
    /// The exact command line, for the report's header.
    pub command: String,
    /// Extra header lines (e.g. which commit of the k-d tree was measured).
    pub remarks: Vec<String>,
}

impl Config {
    /// The full benchmark: the baseline, the corpus meshes and a 5.1M-triangle scene.
    pub fn full() -> Config {
        Config {
            baseline: None,
            meshes: None,
            generated: 5_100_000,
            image: 512,
            random_rays: 262_144,
            packet: 4,
            runs: 3,
            threads: vec![1, 2],
            brute_max_triangles: 20_000,
            brute_rays: 4096,
            params: BuildParams::default(),
            #[cfg(feature = "embree")]
            embree_quality: crate::embree::Quality::High,
            command: String::new(),
            remarks: vec![],
        }
    }

    /// A smoke test that finishes in seconds: one small generated scene, few rays.
    pub fn quick() -> Config {
        Config {
            generated: 3000,
            image: 48,
            random_rays: 2048,
            brute_rays: 512,
            ..Config::full()
        }
    }
}
