//! Scene files give the same bits in every build: random scenes (random rotations a little off
//! unit length as files hold them, offsets, velocities, damping, springs between random bodies,
//! forces at points, gravity) are loaded through the scene reader and stepped under every
//! integrator; the checksums are pinned, so that the default build, the `enhanced-determinism`
//! build (glam `scalar-math`), every forced kernel path and a build for the native CPU must all
//! reproduce them (CI runs this suite in each; the test's name holds `checksum` for its
//! filter). A path from the file into the state that rounds differently between builds fails
//! it, as glam's SIMD `Quat::normalize` did.

use tumble::bevy_ecs::prelude::World;
use tumble::math::DOUBLE_PRECISION;
use tumble::prelude::*;
use tumble::scene::Scene;

/// A small xorshift generator: the same scenes on every machine.
struct Rng(u64);

impl Rng {
    /// Uniform in [−1, 1).
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    fn vec3(&mut self, scale: f64) -> String {
        format!(
            "[{:.6}, {:.6}, {:.6}]",
            scale * self.next(),
            scale * self.next(),
            scale * self.next()
        )
    }
}

/// Random scene `seed` under `integrator`, as a scene file's text.
fn scene_text(seed: u64, integrator: Integrator) -> String {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ seed.wrapping_mul(0x2545_f491_4f6c_dd1d));
    let mut text = format!(
        "name = \"random{seed}\"\n[world]\ndt = 0.0166666\nsteps = 40\nintegrator = \"{}\"\n\
         springs = \"explicit\"\ngravity = [0.0, -9.81, 0.0]\n",
        integrator.name()
    );
    let bodies = 6;
    for i in 0..bodies {
        // Moments that satisfy the triangle inequality (with room for the decimals written),
        // one body near the thin-plate limit.
        let (a, b) = (0.2 + 0.5 * rng.next().abs(), 0.2 + 0.5 * rng.next().abs());
        let c = if i == 0 {
            (a + b) * 0.999
        } else {
            (a + b) * (0.6 + 0.3 * rng.next().abs())
        };
        // A rotation written with seven digits, so a little off unit length.
        let q = [rng.next(), rng.next(), rng.next(), rng.next()];
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        let q = q.map(|x| x / n);
        text.push_str(&format!(
            "[[bodies]]\nname = \"b{i}\"\nmass = {:.4}\ninertia = [{a:.5}, {b:.5}, {c:.5}]\n\
             position = {}\nrotation = [{:.7}, {:.7}, {:.7}, {:.7}]\n\
             linear_velocity = {}\nangular_velocity = {}\n",
            1.0 + rng.next().abs(),
            rng.vec3(3.0),
            q[0],
            q[1],
            q[2],
            q[3],
            rng.vec3(1.0),
            rng.vec3(4.0),
        ));
        if i % 3 == 1 {
            text.push_str("linear_damping = 0.2\nangular_damping = 0.1\n");
        }
    }
    for k in 0..bodies - 1 {
        text.push_str(&format!(
            "[[forces]]\ntype = \"spring\"\na = \"b{k}\"\nb = \"b{}\"\nanchor_a = {}\n\
             anchor_b = {}\nstiffness = {:.3}\ndamping = {}\nrest_length = 1.0\n",
            k + 1,
            rng.vec3(0.2),
            rng.vec3(0.2),
            5.0 + 5.0 * rng.next().abs(),
            if k % 2 == 0 { "0.05" } else { "0.0" },
        ));
    }
    text.push_str(&format!(
        "[[forces]]\ntype = \"constant\"\nbody = \"b2\"\nforce = {}\npoint = {}\n",
        rng.vec3(2.0),
        rng.vec3(0.3)
    ));
    text.push_str(&format!(
        "[[forces]]\ntype = \"torque\"\nbody = \"b4\"\ntorque = {}\n",
        rng.vec3(0.5)
    ));
    text
}

/// The checksum of random scene `seed` under `integrator` after its steps.
fn scene_checksum(seed: u64, integrator: Integrator) -> String {
    let text = scene_text(seed, integrator);
    let scene = Scene::parse("random.toml", &text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let steps = scene.steps();
    let mut built = scene.build();
    for _ in 0..steps {
        built.step();
    }
    let world: &World = &built.world;
    assert!(
        world.resource::<PhysicsErrors>().is_empty(),
        "{integrator}, seed {seed}: {:?}",
        world.resource::<PhysicsErrors>()
    );
    world_checksum(world).to_string()
}

/// Three random scenes per integrator; see the module docs. Re-pin only for a deliberate change
/// of bits, listed in the README.
#[test]
fn random_scene_checksums_are_the_same_in_every_build() {
    let pinned = if DOUBLE_PRECISION {
        PINNED_F64
    } else {
        PINNED_F32
    };
    let measured: Vec<(String, String)> = Integrator::ALL
        .iter()
        .map(|&i| {
            let sums: Vec<String> = (0..3).map(|seed| scene_checksum(seed, i)).collect();
            (i.name().to_owned(), sums.join(" "))
        })
        .collect();
    for (name, sums) in &measured {
        println!("    (\"{name}\", \"{sums}\"),");
    }
    assert_eq!(measured.len(), pinned.len());
    for ((name, sums), (pinned_name, pinned_sums)) in measured.iter().zip(pinned) {
        assert_eq!(name, pinned_name);
        assert_eq!(
            sums, pinned_sums,
            "`{name}`: a build changed the bits of a scene file"
        );
    }
}

const PINNED_F32: &[(&str, &str)] = &[
    (
        "symplectic-euler",
        "09ee1e977e6e86ffb2d15be51af62f02 e31689f0b68d431eeef7d4801eaf196e a56d79aafe87091f334590910d16f791",
    ),
    (
        "symplectic-euler-linear",
        "9f28705014683690a29b990fe293287f 15fb789bfb0196cd297134cc9c4064e6 9c3928c1733bee8ab1cabfd44bc6380f",
    ),
    (
        "lclamp",
        "6ca0491cfa4c35ac373227f4ceec4ad7 35ecc3f62d06caa6a0dd3ce1a93e96ae 84c138c8799e69a8affa6b38f6fb5041",
    ),
    (
        "implicit-gyroscopic",
        "180cbe55a0885bbcbe7d41e808e1a1d2 d7e6fb678a78029e476f2ec20e2710aa 2d6689ea266c7eb314acede9da2e51f9",
    ),
    (
        "splitting",
        "24d0eb56dec2733e6863e59ff4d4f51f 90ae1159d9710b80814d822cc4294d37 8701984ebda259a83b09d76a179e7669",
    ),
    (
        "splitting-xyz",
        "8014c0d258c2db0bf0ec18ce029b81de 200f4188448f36f0b7e004a640267c47 dd8876b49d7c603644476130b8aa92ec",
    ),
    (
        "yoshida4",
        "6171900719a0b906279671868cabed7a 777cb499caa54f58a8c86daa5dc95905 fa195b64cef7223e618b8c72ed58d4d4",
    ),
    (
        "rk4",
        "03d78b4753febff7679d4f0fd5415c9a 6a649604b5eda1775b23a085eba7ff7c 8caa460d5b377dbb1d3aa635d3aee008",
    ),
    (
        "exact",
        "d6feb8e772aeee2f85d833957a695f16 a79e370bbc58360df93866a625e08a9c 2e839b267de92d9d7a6ebea3d049b20c",
    ),
    (
        "exact4",
        "311ee69fb3dfa7f243c8ce9474aa4def 3fb1180a5ca7e757d27cac75b5ad78a1 b19a0c2d1d84ece549e67d47ab330cc4",
    ),
];

const PINNED_F64: &[(&str, &str)] = &[
    (
        "symplectic-euler",
        "e1fe6458cb116749c7912ab504bac7fa eb6f33020c827f4cdc2c289aa7acdc7c e85859e9cea4c5ac023004e8dd02a04c",
    ),
    (
        "symplectic-euler-linear",
        "9b4cd19bb1154e7d1cfba0db5eaf5a39 827b26d2088698bad36cb60c8002ff9a 888e2e5c4c1d444e3c3822b0cee4a55b",
    ),
    (
        "lclamp",
        "fc4a1e9c3379ce958d02f965b09b24ed fab1f281817a4c120cdec5a78b1689c8 d884e97a9f156cf074344d0a93c1bf38",
    ),
    (
        "implicit-gyroscopic",
        "13b02c20f7c41e8c0eb7642b9dc07fb9 a084fdf3d82d1e393e450b94b4f78f5f 060fba8106b5f6bac77c64bb7dd71668",
    ),
    (
        "splitting",
        "7e31b771ee3ca695e79190a170e1a984 19b2ec993a3b4a5cecbbfb1549daef7f 26ec8e0f081fc66051c5bb2402389ec3",
    ),
    (
        "splitting-xyz",
        "e30414cc787b6fad76727aff4155dae1 e6ca56697bd65fe6732502bd0a981a32 57aa7f6cb3aa60d0ae27f8e2937f50b7",
    ),
    (
        "yoshida4",
        "2d546c727b4f56dbb5043d77143e30e3 b49c0e772e30021a745094cb90880dd9 cce99e2af5b89f3475e82cd524ce003a",
    ),
    (
        "rk4",
        "0418e291081333fc6b1e31066ab41ae5 2161ce759fc740def0ff4a3e7e7d60b7 06fa8c4a9a1e4c4c6b13528fc53ef5a2",
    ),
    (
        "exact",
        "8868f9715613166467f00911366f8763 ef04bc8aad458570338e4b46ad5105d7 53512c5b29b68ac3b59bbdda7ab1c5c1",
    ),
    (
        "exact4",
        "7eefc1036b3b5b7960dd8d345048a1f5 a04a6717dc1b8f13d59f07a5388c4174 403e80aef82543df52b21d2070899be1",
    ),
];
