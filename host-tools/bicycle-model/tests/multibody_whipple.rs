//! The multibody description reduces exactly to the benchmark's closed
//! forms when both contacts roll without slip and torso and twist are
//! locked: the derivation of the extended model checked against Meijaard et
//! al. (2007), Appendix A.

use std::path::Path;

use nalgebra::DMatrix;
use wobble_model::multibody::{self, constrained_whipple, Frame, Geometry};
use wobble_model::whipple::Benchmark;
use wobble_model::ParamSet;

fn benchmark() -> Benchmark {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/benchmark.toml");
    Benchmark::from_set(&ParamSet::load(&path).unwrap()).unwrap()
}

fn assert_same(got: &DMatrix<f64>, want: &nalgebra::Matrix2<f64>, what: &str) {
    let diff = (0..2)
        .flat_map(|i| (0..2).map(move |j| (i, j)))
        .map(|(i, j)| (got[(i, j)] - want[(i, j)]).abs())
        .fold(0.0, f64::max);
    assert!(
        diff < 1e-12,
        "{what}: multibody {got} vs closed form {want}"
    );
}

#[test]
fn benchmark_bodies_reduce_to_the_closed_forms() {
    let b = benchmark();
    let geo = Geometry {
        wheelbase: b.wheelbase,
        trail: b.trail,
        steer_axis_tilt: b.steer_axis_tilt,
        rear_radius: b.rear_wheel.radius,
        front_radius: b.front_wheel.radius,
        hip_z: -0.8,
        twist_z: -0.7,
        twist_axis_angle: 0.0,
        gravity: b.gravity,
    };
    let bodies = [
        multibody::wheel_body(Frame::Rear, 0.0, &b.rear_wheel),
        multibody::frame_body(Frame::Rear, &b.rear_frame),
        multibody::frame_body(Frame::FrontUpper, &b.front_frame),
        multibody::wheel_body(Frame::FrontSub, b.wheelbase, &b.front_wheel),
    ];
    let lin = multibody::linearise(&geo, &bodies);
    let [m, c1, k0g, k2] = constrained_whipple(&lin);
    let want = b.matrices();
    assert_same(&m, &want.m, "M");
    assert_same(&c1, &want.c1, "C1");
    assert_same(&(k0g / b.gravity), &want.k0, "K0");
    assert_same(&k2, &want.k2, "K2");
}
