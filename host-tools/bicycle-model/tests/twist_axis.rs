//! The orientation of the steering head's twist axis (`steer_head.axis_angle`,
//! a structural variant of the identification): turning the axis in the
//! plane of symmetry turns how the twist tilts and steers the front wheel,
//! as worked by hand. A twist `beta` about the unit axis
//! `a = (cos t, 0, -sin t)`, `t` the steer axis tilt plus the axis angle,
//! rolls the wheel plane by `beta cos t` (the axis's x part: camber) and
//! turns its heading by `beta sin t` (the axis's vertical part).

mod support;

use support::bundled;
use wobble_model::multibody::BETA;
use wobble_model::wobble::WobbleModel;
use wobble_model::{ParamSet, Quantity};

fn with_angle(file: &str, deg: f64) -> ParamSet {
    let mut set = bundled(file);
    set.insert(
        "steer_head.axis_angle",
        Quantity {
            value: deg,
            unit: "deg".into(),
            source: "test".into(),
        },
    );
    set
}

#[test]
fn the_twist_cambers_and_steers_the_front_wheel_by_its_axis() {
    let tilt = 19f64.to_radians();
    for deg in [0.0, -19.0, 20.0, 45.0] {
        let m = WobbleModel::from_set(&with_angle("paper-test-bicycle.toml", deg)).unwrap();
        let front = &m.lin.tyres[0];
        let t = tilt + f64::to_radians(deg);
        let (camber, heading) = (front.camber_q[(0, BETA)], front.slip_q[(0, BETA)]);
        assert!(
            (camber.abs() - t.cos()).abs() < 1e-12,
            "{deg} deg: camber {camber}"
        );
        assert!(
            (heading.abs() - t.sin()).abs() < 1e-12,
            "{deg} deg: heading {heading}"
        );
        // The rear wheel does not twist.
        assert_eq!(m.lin.tyres[1].camber_q[(0, BETA)], 0.0);
    }
}

/// A horizontal axis only cambers: the twist then leaves the front wheel's
/// heading alone, and the default is the axis perpendicular to the steer
/// axis.
#[test]
fn a_horizontal_axis_only_cambers_and_the_default_is_perpendicular() {
    let flat = WobbleModel::from_set(&with_angle("paper-test-bicycle.toml", -19.0)).unwrap();
    assert!(flat.lin.tyres[0].slip_q[(0, BETA)].abs() < 1e-12);
    // The first test bicycle's file does not name the angle.
    let default = WobbleModel::from_set(&bundled("test-bicycle.toml")).unwrap();
    let perpendicular = WobbleModel::from_set(&with_angle("test-bicycle.toml", 0.0)).unwrap();
    assert_eq!(default.lin, perpendicular.lin);
}
