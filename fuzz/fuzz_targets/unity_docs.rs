//! The Unity document splitter and the YAML subset parser on arbitrary scene text:
//! every document header is split off and every body parsed and walked.
#![no_main]

use libfuzzer_sys::fuzz_target;
use unity::{docs, yaml::Node};

fn walk(n: &Node, depth: usize) {
    // Touch every accessor the converter uses on bodies.
    let _ = (
        n.as_f32(),
        n.as_i64(),
        n.vec3(),
        n.quat(),
        n.color(),
        n.as_str(),
    );
    if depth > 64 {
        return;
    }
    for c in n.as_seq() {
        walk(c, depth + 1);
    }
    for (k, v) in n.as_map() {
        let _ = n.get(k);
        walk(v, depth + 1);
    }
}

fuzz_target!(|data: &[u8]| {
    let _ = docs::is_text_yaml(data);
    let text = String::from_utf8_lossy(data);
    for d in docs::split(&text) {
        if let Some((line, _)) = unity::yaml::malformed(d.body) {
            assert!(line >= 1 && line <= d.body.lines().count().max(1));
        }
        let body = d.parse();
        walk(&body, 0);
        let _ = unity::graph::fref(body.get("m_GameObject"));
    }
});
