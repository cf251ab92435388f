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
        "edb59256137afdc0e924c820e164e8fb beac8f4be7624bc43f3245f1f8b4795f 5c93d92f03ea01e21301cfe29c09c086",
    ),
    (
        "symplectic-euler-linear",
        "675125aac4721bb4976815f340b8f278 b1a827186324ac7712a486d6d3db3ea2 b27ea581421fa9823f847f67b927664d",
    ),
    (
        "lclamp",
        "3cc4d5b364826d9f30e45f362f34d461 2ecd7b7ac85b0128e38b249032790c25 5e0358ca9dcca5e3cc85917cdcce2b67",
    ),
    (
        "implicit-gyroscopic",
        "e6e53ede24b272e10d76d3ba97af33fe ca2c7d64503d477764bb4925c1282055 20897df6d029b7a30598606e6f21488e",
    ),
    (
        "splitting",
        "24d0eb56dec2733e6863e59ff4d4f51f 90ae1159d9710b80814d822cc4294d37 8701984ebda259a83b09d76a179e7669",
    ),
    (
        "splitting-xyz",
        "0cc939640e70838bcda68288208c1a1b 84674756e4bcbdc0aa743731b94d8b5a d03dcae7aea9d44fc7931e655b3fd22f",
    ),
    (
        "yoshida4",
        "6171900719a0b906279671868cabed7a 777cb499caa54f58a8c86daa5dc95905 fa195b64cef7223e618b8c72ed58d4d4",
    ),
    (
        "rk4",
        "050bc3ac879f19b867115c528d53a68a 9bb4ac74f4a6ed5881d5bcc048f12e33 7192971284bf8a6e364f9484f9f7e359",
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
        "431ca4fdb7b839f7955e3e466c26b6d4 ef5c726f1fa615a4f7074b3d47940c0f b40634c48b13568fceb23c9c6dcb0244",
    ),
    (
        "symplectic-euler-linear",
        "2369c3c04dfbfee036bfa04bc3f8dc8d 077dfa9df1ca3c0e926261872121163c db11bf7728f5b1324cbf52d512348a1f",
    ),
    (
        "lclamp",
        "05d1846826261d5fec9282d131161104 dc28eff1a176144916dad9fe31966f56 084fc9f415396e647dfba50aa10f14d7",
    ),
    (
        "implicit-gyroscopic",
        "bd696f785cf3eb8920b9cbe82e411bb8 2ebd4abf87b8bcb4187c9bf58710fa18 9d03a983a5a85de3a7f62c03ae41447b",
    ),
    (
        "splitting",
        "7e31b771ee3ca695e79190a170e1a984 19b2ec993a3b4a5cecbbfb1549daef7f 26ec8e0f081fc66051c5bb2402389ec3",
    ),
    (
        "splitting-xyz",
        "e30414cc787b6fad76727aff4155dae1 78cc34d8a64cd3df24dbb729a52fe2fc 57aa7f6cb3aa60d0ae27f8e2937f50b7",
    ),
    (
        "yoshida4",
        "2d546c727b4f56dbb5043d77143e30e3 b49c0e772e30021a745094cb90880dd9 cce99e2af5b89f3475e82cd524ce003a",
    ),
    (
        "rk4",
        "5b78d5d3517ef9055a7b7c938af74528 925d66a75dce930abf2f18edbb5e177f 078480bc4b35fc880f76bfde4c621088",
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
