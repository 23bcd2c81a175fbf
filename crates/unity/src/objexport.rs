//! World-space OBJ export of a soup (`soup2obj`).

use formats::Soup;
use std::fmt::Write;

/// One `o <object name>` per run of triangles of the same object, faces in soup order,
/// each corner with its own position and normal.
pub fn to_obj(soup: &Soup) -> String {
    let mut s = String::with_capacity(soup.triangles.len() * 200);
    let _ = writeln!(
        s,
        "# unitrace soup: {} triangles, {} objects",
        soup.triangles.len(),
        soup.objects.len()
    );
    let mut current = u32::MAX;
    for i in 0..soup.triangle_count() {
        let (t, n) = (soup.corners(i), soup.corner_normals(i));
        let obj = soup.tri_object[i];
        if obj != current {
            current = obj;
            let name = soup
                .objects
                .get(obj as usize)
                .map(|o| o.name.as_str())
                .unwrap_or("?");
            let name: String = name
                .chars()
                .map(|c| if c == '\n' || c == '\r' { ' ' } else { c }) // the rest of an `o` line is the name
                .collect();
            let _ = writeln!(s, "o {name}");
        }
        for v in t {
            let _ = writeln!(s, "v {} {} {}", v.x, v.y, v.z);
        }
        for v in n {
            let _ = writeln!(s, "vn {} {} {}", v.x, v.y, v.z);
        }
        let b = i * 3;
        let _ = writeln!(
            s,
            "f {}//{} {}//{} {}//{}",
            b + 1,
            b + 1,
            b + 2,
            b + 2,
            b + 3,
            b + 3
        );
    }
    s
}
