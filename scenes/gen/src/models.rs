//! The baseline's models, rebuilt from tessellated primitives at the exact triangle counts
//! of the original Haskell ray tracer's scene, so the two trace scenes of the same size. Units are metres, +Y up, each model faces +Z and stands on y = 0 (the mirror
//! sphere is centred on the origin). Every model is symmetric in X, so Unity's X flip on
//! OBJ import does not change how it looks.
//!
//! The per-part counts are written next to each part; `tests::counts_match_the_original` holds
//! the totals to the triangle.

use crate::mesh::{box_grid, cone, cylinder, disc, leaf, tapered, torus, tube, uv_sphere, Mesh};
use glam::{Affine3A, Quat, Vec3};
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// One baseline model: its OBJ group name (also the Unity mesh name) and its mesh.
pub struct Model {
    pub name: &'static str,
    pub mesh: Mesh,
}

pub const MIRROR_SPHERE_TRIANGLES: usize = 6_240;
pub const MAN_TRIANGLES: usize = 4_704;
pub const CAR_TRIANGLES: usize = 10_385;
pub const PIG_TRIANGLES: usize = 2_454;
pub const TREE_TRIANGLES: usize = 6_565;

/// Every baseline model, in the order the scene lists them.
pub fn all() -> Vec<Model> {
    vec![
        Model {
            name: "MirrorSphere",
            mesh: mirror_sphere(),
        },
        Model {
            name: "Man",
            mesh: man(),
        },
        Model {
            name: "Car",
            mesh: car(),
        },
        Model {
            name: "Pig",
            mesh: pig(),
        },
        Model {
            name: "Tree",
            mesh: tree(),
        },
    ]
}

fn at(scale: Vec3, rotation: Quat, translation: Vec3) -> Affine3A {
    Affine3A::from_scale_rotation_translation(scale, rotation, translation)
}

fn moved(scale: Vec3, translation: Vec3) -> Affine3A {
    at(scale, Quat::IDENTITY, translation)
}

/// A unit-height Y primitive stretched from `a` to `b` with the given radius.
fn between(a: Vec3, b: Vec3, radius: f32) -> Affine3A {
    let d = b - a;
    at(
        Vec3::new(radius, d.length(), radius),
        Quat::from_rotation_arc(Vec3::Y, d.normalize()),
        a,
    )
}

/// A unit Y-facing disc (or cone) turned to face `normal`.
fn facing(normal: Vec3, radius: f32, centre: Vec3) -> Affine3A {
    at(
        Vec3::splat(radius),
        Quat::from_rotation_arc(Vec3::Y, normal),
        centre,
    )
}

/// Both mirror images of a part placed at +X (the models are symmetric in X).
fn pair(m: &mut Mesh, part: &Mesh, xf: Affine3A) {
    m.add(part, xf);
    m.add(part, Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0)) * xf);
}

/// The mirror sphere: radius 1, 80 segments × 40 rings = 6,240.
pub fn mirror_sphere() -> Mesh {
    uv_sphere(80, 40)
}

/// A standing man, 1.8 m tall: 4,704.
pub fn man() -> Mesh {
    let mut m = Mesh::default();
    let leg = cylinder(16, 10); // 352
    let foot = box_grid(2); // 48
    let shoulder = uv_sphere(16, 10); // 288
    let arm = cylinder(16, 8); // 288
    let hand = uv_sphere(12, 8); // 168
    let eye = uv_sphere(8, 5); // 64
    pair(
        &mut m,
        &leg,
        between(
            Vec3::new(0.11, 0.06, 0.0),
            Vec3::new(0.11, 0.95, 0.0),
            0.085,
        ),
    );
    pair(
        &mut m,
        &foot,
        moved(Vec3::new(0.12, 0.08, 0.26), Vec3::new(0.11, 0.04, 0.05)),
    );
    m.add(
        &uv_sphere(24, 12),
        moved(Vec3::new(0.2, 0.13, 0.13), Vec3::new(0.0, 0.95, 0.0)),
    ); // hips 528
    m.add(
        &uv_sphere(32, 16),
        moved(Vec3::new(0.23, 0.34, 0.15), Vec3::new(0.0, 1.26, 0.0)),
    ); // torso 960
    pair(
        &mut m,
        &shoulder,
        moved(Vec3::splat(0.075), Vec3::new(0.25, 1.47, 0.0)),
    );
    pair(
        &mut m,
        &arm,
        between(
            Vec3::new(0.27, 1.47, 0.0),
            Vec3::new(0.36, 0.92, 0.03),
            0.05,
        ),
    );
    pair(
        &mut m,
        &hand,
        moved(Vec3::splat(0.06), Vec3::new(0.365, 0.88, 0.03)),
    );
    m.add(
        &cylinder(16, 1),
        between(Vec3::new(0.0, 1.55, 0.0), Vec3::new(0.0, 1.64, 0.0), 0.05),
    ); // neck 64
    m.add(
        &uv_sphere(24, 16),
        moved(Vec3::new(0.11, 0.13, 0.12), Vec3::new(0.0, 1.74, 0.0)),
    ); // head 720
    pair(
        &mut m,
        &eye,
        moved(Vec3::splat(0.018), Vec3::new(0.04, 1.765, 0.105)),
    );
    m.add(
        &cone(8),
        between(Vec3::new(0.0, 1.72, 0.11), Vec3::new(0.0, 1.72, 0.15), 0.02),
    ); // nose 16
    m
}

/// A car, 4.2 m long, 1.8 m wide: 10,385 (the hubcaps, lights and badge are open discs).
pub fn car() -> Mesh {
    let mut m = Mesh::default();
    m.add(
        &box_grid(18),
        moved(Vec3::new(1.8, 0.6, 4.2), Vec3::new(0.0, 0.65, 0.0)),
    ); // body 3,888
    m.add(
        &box_grid(14),
        moved(Vec3::new(1.5, 0.55, 2.2), Vec3::new(0.0, 1.225, -0.2)),
    ); // cabin 2,352
    let tyre = torus(32, 12, 0.28, 0.12); // 768
    let hubcap = disc(32); // 32
    let axle = Quat::from_rotation_z(FRAC_PI_2);
    for z in [1.35, -1.35] {
        pair(&mut m, &tyre, at(Vec3::ONE, axle, Vec3::new(0.92, 0.4, z)));
        pair(
            &mut m,
            &hubcap,
            facing(Vec3::X, 0.2, Vec3::new(0.96, 0.4, z)),
        );
    }
    pair(
        &mut m,
        &disc(24),
        facing(Vec3::Z, 0.14, Vec3::new(0.6, 0.75, 2.101)),
    ); // headlights 48
    pair(
        &mut m,
        &disc(16),
        facing(Vec3::NEG_Z, 0.1, Vec3::new(0.65, 0.8, -2.101)),
    ); // taillights 32
    let bumper = cylinder(24, 4); // 240
    for z in [2.15, -2.15] {
        m.add(
            &bumper,
            between(Vec3::new(-0.95, 0.42, z), Vec3::new(0.95, 0.42, z), 0.08),
        );
    }
    pair(
        &mut m,
        &box_grid(2),
        moved(Vec3::new(0.2, 0.12, 0.08), Vec3::new(0.95, 1.05, 0.8)),
    ); // mirrors 96
    m.add(
        &cylinder(12, 2),
        between(Vec3::new(0.5, 0.3, -2.05), Vec3::new(0.5, 0.3, -2.35), 0.05),
    ); // exhaust 72
    m.add(
        &cylinder(6, 1),
        between(
            Vec3::new(-0.6, 1.5, -1.1),
            Vec3::new(-0.6, 2.2, -1.15),
            0.01,
        ),
    ); // antenna 24
    pair(
        &mut m,
        &disc(12),
        facing(Vec3::Z, 0.05, Vec3::new(0.55, 0.55, 2.101)),
    ); // fog lights 24
    let plate = box_grid(2); // 48
    for z in [2.11, -2.11] {
        m.add(
            &plate,
            moved(Vec3::new(0.5, 0.12, 0.02), Vec3::new(0.0, 0.62, z)),
        );
    }
    m.add(
        &disc(25),
        facing(Vec3::Z, 0.07, Vec3::new(0.0, 0.82, 2.101)),
    ); // badge 25
    let flap = box_grid(1); // 12
    for z in [0.85, -1.85] {
        pair(
            &mut m,
            &flap,
            moved(Vec3::new(0.25, 0.22, 0.02), Vec3::new(0.92, 0.22, z)),
        );
    }
    m
}

/// A pig, 1.1 m long: 2,454.
pub fn pig() -> Mesh {
    let mut m = Mesh::default();
    m.add(
        &uv_sphere(32, 20),
        moved(Vec3::new(0.32, 0.28, 0.52), Vec3::new(0.0, 0.55, 0.0)),
    ); // body 1,216
    m.add(
        &uv_sphere(24, 14),
        moved(Vec3::splat(0.22), Vec3::new(0.0, 0.68, 0.56)),
    ); // head 624
    m.add(
        &cylinder(16, 1),
        between(Vec3::new(0.0, 0.64, 0.72), Vec3::new(0.0, 0.64, 0.84), 0.09),
    ); // snout 64
    let leg = cylinder(12, 2); // 72
    for z in [0.28, -0.28] {
        pair(
            &mut m,
            &leg,
            between(Vec3::new(0.16, 0.0, z), Vec3::new(0.16, 0.45, z), 0.065),
        );
    }
    let ear = cone(8); // 16
    let ear_tilt = Quat::from_rotation_z(-0.5) * Quat::from_rotation_x(0.3);
    pair(
        &mut m,
        &ear,
        at(
            Vec3::new(0.07, 0.12, 0.03),
            ear_tilt,
            Vec3::new(0.12, 0.84, 0.55),
        ),
    );
    pair(
        &mut m,
        &uv_sphere(8, 5),
        moved(Vec3::splat(0.025), Vec3::new(0.08, 0.74, 0.75)),
    ); // eyes 128
       // Curly tail, a helix leaving the rump: 2·6·8 + 6 = 102.
    let path: Vec<Vec3> = (0..9)
        .map(|k| {
            let a = k as f32 * 0.4 * PI;
            Vec3::new(
                0.045 * a.sin(),
                0.62 + 0.045 * (1.0 - a.cos()),
                -0.48 - 0.025 * k as f32,
            )
        })
        .collect();
    m.add(&tube(&path, 0.018, 6), Affine3A::IDENTITY);
    m
}

/// A tree, about 4.3 m tall, trunk plus bumpy foliage and 245 loose leaves: 6,565.
pub fn tree() -> Mesh {
    let mut m = Mesh::default();
    m.add(
        &tapered(24, 8, 0.22, 0.14),
        moved(Vec3::new(1.0, 2.2, 1.0), Vec3::ZERO),
    ); // trunk 432
    let crowns = [
        (Vec3::new(0.0, 3.0, 0.0), 1.25),
        (Vec3::new(0.8, 2.5, 0.15), 0.8),
        (Vec3::new(-0.8, 2.5, 0.15), 0.8),
    ];
    m.add(
        &bumpy(uv_sphere(64, 32), 0.08, 5.0),
        moved(Vec3::splat(crowns[0].1), crowns[0].0),
    ); // 3,968
    let blob = bumpy(uv_sphere(32, 16), 0.06, 4.0); // 960
    for (centre, radius) in &crowns[1..] {
        m.add(&blob, moved(Vec3::splat(*radius), *centre));
    }
    // Loose leaves sprinkled over the crowns, each one triangle facing out: 245.
    let leaf = leaf();
    let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
    for i in 0..245 {
        let (centre, radius) = crowns[[0, 0, 1, 2][i % 4]];
        let dir = loop {
            let v = Vec3::new(
                rng.unit() * 2.0 - 1.0,
                rng.unit() * 2.0 - 1.0,
                rng.unit() * 2.0 - 1.0,
            );
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                break v / l;
            }
        };
        let spin = Quat::from_rotation_z(rng.unit() * TAU);
        let rot = Quat::from_rotation_arc(Vec3::Z, dir) * spin;
        m.add(
            &leaf,
            at(Vec3::splat(0.2), rot, centre + dir * radius * 1.04),
        );
    }
    m
}

/// Push a unit sphere's vertices in and out so foliage looks leafy rather than polished.
fn bumpy(mut m: Mesh, amplitude: f32, frequency: f32) -> Mesh {
    for p in &mut m.positions {
        let f = frequency;
        let bump = (f * p.x + 1.3).sin() * (f * p.y + 0.7).sin() * (f * p.z + 2.1).sin();
        *p *= 1.0 + amplitude * bump;
    }
    // The surface moved: its normals must follow.
    m.with_normals()
}

/// Small deterministic generator (xorshift64*): the leaves must land in the same place on
/// every run so the committed OBJ is reproducible.
struct XorShift(u64);

impl XorShift {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let r = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (r >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_match_the_original() {
        assert_eq!(mirror_sphere().triangle_count(), MIRROR_SPHERE_TRIANGLES);
        assert_eq!(man().triangle_count(), MAN_TRIANGLES);
        assert_eq!(car().triangle_count(), CAR_TRIANGLES);
        assert_eq!(pig().triangle_count(), PIG_TRIANGLES);
        assert_eq!(tree().triangle_count(), TREE_TRIANGLES);
    }

    fn bounds(m: &Mesh) -> (Vec3, Vec3) {
        m.positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            })
    }

    #[test]
    fn models_have_their_real_world_sizes() {
        let (lo, hi) = bounds(&man());
        assert!(
            (lo.y - 0.0).abs() < 0.01 && (hi.y - 1.87).abs() < 0.05,
            "man {lo} {hi}"
        );
        let (lo, hi) = bounds(&car());
        assert!(lo.y.abs() < 0.01, "car wheels on the ground: {lo}");
        assert!((hi.z - lo.z - 4.58).abs() < 0.05, "car length {lo} {hi}");
        let (lo, hi) = bounds(&pig());
        assert!(lo.y.abs() < 0.01 && hi.y < 1.0, "pig {lo} {hi}");
        let (lo, hi) = bounds(&tree());
        assert!(
            lo.y.abs() < 0.01 && hi.y > 4.0 && hi.y < 4.6,
            "tree {lo} {hi}"
        );
        let (lo, hi) = bounds(&mirror_sphere());
        assert!((lo + Vec3::ONE).length() < 1e-5 && (hi - Vec3::ONE).length() < 1e-5);
    }

    #[test]
    fn models_are_finite_with_unit_normals() {
        for model in all() {
            let m = &model.mesh;
            assert_eq!(m.normals.len(), m.positions.len(), "{}", model.name);
            assert!(m.positions.iter().all(|p| p.is_finite()), "{}", model.name);
            assert!(
                m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3),
                "{} has a zero normal",
                model.name
            );
        }
    }
}
