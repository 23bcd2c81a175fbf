//! Whether the contenders agree with the k-d tree, ray by ray, and brute force's verdict
//! where they do not.

use crate::contenders::{Brute, Found, Tracer};
use crate::results::{AgreeRow, Kind, Referee};
use glam::Vec3;
use kdtree::testkit::brute;
use kdtree::Ray;

/// Same closest hit: both miss, or the same triangle, or (for ties at shared edges and
/// coincident faces) distances within 1e-4 relative.
pub fn same_closest(a: Found, b: Found) -> bool {
    match (a.is_hit(), b.is_hit()) {
        (false, false) => true,
        (true, true) => a.prim == b.prim || (a.t - b.t).abs() <= 1e-4 * a.t.abs().max(b.t.abs()),
        _ => false,
    }
}

/// One contender's answers to one ray set.
pub(crate) enum Answers {
    Closest(Vec<Found>),
    Occluded(Vec<bool>),
}

/// At most this many disagreements per ray set are settled by brute force (each costs
/// a pass over every triangle).
pub const REFEREE_RAYS: usize = 200;

/// Compare `other`'s answers with the k-d tree's (`reference`, indexed through `idx`
/// when `other` ran on a subset). With `referee` triangles, up to [`REFEREE_RAYS`]
/// disagreements are settled by brute force. The row's log lines are [`summary`]'s.
#[allow(clippy::too_many_arguments)]
pub(crate) fn compare(
    scene: &str,
    other: &str,
    kind: Kind,
    rays: &[Ray],
    reference: &Answers,
    answers: &Answers,
    idx: Option<&[usize]>,
    referee: Option<&[[Vec3; 3]]>,
) -> AgreeRow {
    let at = |j: usize| idx.map_or(j, |idx| idx[j]);
    // (ray index, the tree's answer, the other's answer) for every disagreement.
    let mut differ: Vec<(usize, Found, Found)> = vec![];
    let compared = match (reference, answers) {
        (Answers::Closest(r), Answers::Closest(a)) => {
            for (j, b) in a.iter().enumerate() {
                let i = at(j);
                if !same_closest(r[i], *b) {
                    differ.push((i, r[i], *b));
                }
            }
            a.len()
        }
        (Answers::Occluded(r), Answers::Occluded(a)) => {
            // Occlusion as a hit at t = 0 on no particular triangle, to share the code.
            let f = |o: bool| Found {
                t: if o { 0.0 } else { f32::INFINITY },
                prim: if o { 0 } else { u32::MAX },
                ..Found::default()
            };
            for (j, b) in a.iter().enumerate() {
                let i = at(j);
                if r[i] != *b {
                    differ.push((i, f(r[i]), f(*b)));
                }
            }
            a.len()
        }
        _ => unreachable!("answers of one kind are compared with the same kind"),
    };
    let mut row = AgreeRow {
        scene: scene.into(),
        other: other.into(),
        kind,
        compared,
        disagreements: differ.len(),
        examples: vec![],
        referee: None,
    };
    let show = |f: Found| {
        if !f.is_hit() {
            "miss".to_string()
        } else if kind.any_hit() {
            "occluded".to_string()
        } else {
            format!("t={} prim={}", f.t, f.prim)
        }
    };
    for (i, k, o) in differ.iter().take(3) {
        row.examples.push(format!(
            "{} ray {i} {:?}: kdtree {}, {other} {}",
            kind.name(),
            rays[*i],
            show(*k),
            show(*o)
        ));
    }
    if let Some(tris) = referee.filter(|_| !differ.is_empty()) {
        let mut r = Referee::default();
        for (i, k, o) in differ.iter().take(REFEREE_RAYS) {
            let ray = &rays[*i];
            let truth = if kind.any_hit() {
                let occ = brute::occluded_f64(tris, ray);
                (occ == k.is_hit(), occ == o.is_hit())
            } else {
                let b = Brute(tris).closest(ray);
                (same_closest(b, *k), same_closest(b, *o))
            };
            r.checked += 1;
            r.kdtree_right += usize::from(truth.0);
            r.other_right += usize::from(truth.1);
        }
        row.referee = Some(r);
    }
    row
}

/// The log lines for one comparison: the count, brute force's verdict, a few examples.
pub(crate) fn summary(row: &AgreeRow) -> Vec<String> {
    let (other, kind) = (&row.other, row.kind);
    let mut lines = vec![];
    let referee_note = row.referee.map_or(String::new(), |r| {
        format!(
            "; brute force on {} of them sides with kdtree {} times, with {other} {} times",
            r.checked, r.kdtree_right, r.other_right
        )
    });
    lines.push(format!(
        "  agreement kdtree vs {other} ({}): {} of {} rays differ{referee_note}",
        kind.name(),
        row.disagreements,
        row.compared
    ));
    for e in &row.examples {
        lines.push(format!("    {e}"));
    }
    lines
}

/// Indices of every `len / n`-th element (at most `n`), spread over the whole set.
pub(crate) fn subset_indices(len: usize, n: usize) -> Vec<usize> {
    if len <= n {
        return (0..len).collect();
    }
    let stride = len / n.max(1);
    (0..len).step_by(stride).take(n).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_agreement_rules() {
        let hit = |t, prim| Found {
            t,
            prim,
            u: 0.0,
            v: 0.0,
        };
        assert!(same_closest(Found::default(), Found::default()));
        assert!(same_closest(hit(2.0, 3), hit(2.5, 3)));
        assert!(same_closest(hit(2.0, 3), hit(2.0001, 4)));
        assert!(!same_closest(hit(2.0, 3), hit(2.1, 4)));
        assert!(!same_closest(hit(2.0, 3), Found::default()));
    }

    #[test]
    fn brute_force_settles_disagreements() {
        let tris = [[
            Vec3::new(-1.0, -1.0, 2.0),
            Vec3::new(1.0, -1.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        ]];
        let rays = [
            Ray::new(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY),
            Ray::new(Vec3::new(5.0, 0.0, 0.0), Vec3::Z, 0.0, f32::INFINITY),
        ];
        let hit = Found {
            t: 2.0,
            prim: 0,
            u: 0.25,
            v: 0.5,
        };
        // The tree is right on ray 0 (the other misses); the other is wrong on ray 1 too.
        let reference = Answers::Closest(vec![hit, Found::default()]);
        let other = Answers::Closest(vec![Found::default(), hit]);
        let closest = compare(
            "t",
            "X",
            Kind::Primary,
            &rays,
            &reference,
            &other,
            None,
            Some(&tris),
        );
        let occ_ref = Answers::Occluded(vec![true, false]);
        let occ_other = Answers::Occluded(vec![true, true]);
        let shadow = compare(
            "t",
            "X",
            Kind::Shadow,
            &rays,
            &occ_ref,
            &occ_other,
            None,
            Some(&tris),
        );
        let rows = [closest, shadow];
        assert_eq!((rows[0].compared, rows[0].disagreements), (2, 2));
        let want = Referee {
            checked: 2,
            kdtree_right: 2,
            other_right: 0,
        };
        assert_eq!(rows[0].referee, Some(want));
        assert!(!rows[0].ok());
        assert_eq!((rows[1].compared, rows[1].disagreements), (2, 1));
        let want = Referee {
            checked: 1,
            kdtree_right: 1,
            other_right: 0,
        };
        assert_eq!(rows[1].referee, Some(want));
        assert!(rows[1].examples[0].contains("kdtree miss, X occluded"));
    }

    #[test]
    fn subset_indices_spread() {
        assert_eq!(subset_indices(10, 20), (0..10).collect::<Vec<_>>());
        assert_eq!(subset_indices(100, 4), vec![0, 25, 50, 75]);
    }
}
