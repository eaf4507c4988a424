//! The changed bicycles of the seed paper's parameter study (section 4),
//! each built from a `wobble` parameter set as the text describes it: a
//! parameter scaled (its Figure 7 halves and doubles), a load as a mass
//! added to the body that carries it, the steer axis angle changed at
//! constant fork offset and wheelbase, the rider made lighter or moved.

use crate::params::{ParamError, ParamSet, Problem, Quantity, Unit};
use crate::whipple::Body;

/// `set` with each key multiplied by its factor (in its file unit).
///
/// # Errors
/// When a key is not in the set.
pub fn scaled(set: &ParamSet, changes: &[(&str, f64)]) -> Result<ParamSet, ParamError> {
    let mut out = set.clone();
    for (key, factor) in changes {
        let v = out.value(key)?;
        out.set_value(key, v * factor, "scaled for the parameter study")?;
    }
    Ok(out)
}

/// The name of the rider's whole mass as a key of [`scaled_key`].
pub const RIDER_MASS: &str = "rider.mass";

/// `set` with `key` scaled by `factor`: a parameter of the file, or
/// [`RIDER_MASS`], the rider scaled whole by [`rider_of_mass`] (the
/// paper's Figure 9).
///
/// # Errors
/// When the key is not in the set (or the set has no `[rider_legs]`, for
/// the rider's mass).
pub fn scaled_key(set: &ParamSet, key: &str, factor: f64) -> Result<ParamSet, ParamError> {
    if key == RIDER_MASS {
        rider_of_mass(set, factor * rider_mass_kg(set)?)
    } else {
        scaled(set, &[(key, factor)])
    }
}

/// Writes `b` into `section` of `set`, in SI units (the inverse of
/// [`Body::from_set`]).
fn put(set: &mut ParamSet, section: &str, b: &Body, why: &str) -> Result<(), ParamError> {
    for (k, v, unit) in [
        ("mass", b.mass, Unit::Mass),
        ("x", b.x, Unit::Length),
        ("z", b.z, Unit::Length),
        ("inertia_xx", b.inertia_xx, Unit::Inertia),
        ("inertia_xz", b.inertia_xz, Unit::Inertia),
        ("inertia_yy", b.inertia_yy, Unit::Inertia),
        ("inertia_zz", b.inertia_zz, Unit::Inertia),
    ] {
        let key = format!("{section}.{k}");
        let factor = set
            .quantity(&key)
            .and_then(|q| unit.factor(&q.unit))
            .ok_or_else(|| set.error(&key, Problem::Unknown))?;
        set.set_value(&key, v / factor, why)?;
    }
    Ok(())
}

/// `set` with a point mass of `mass_kg` at `(x, z)` (m, the benchmark's
/// axes) added to the body of `section`.
///
/// # Errors
/// When the section is not a body of the set.
pub fn loaded(
    set: &ParamSet,
    section: &str,
    mass_kg: f64,
    x: f64,
    z: f64,
) -> Result<ParamSet, ParamError> {
    let mut out = set.clone();
    let load = Body {
        mass: mass_kg,
        x,
        z,
        inertia_xx: 0.0,
        inertia_xz: 0.0,
        inertia_yy: 0.0,
        inertia_zz: 0.0,
    };
    put(
        &mut out,
        section,
        &Body::from_set(set, section)?.lump(&load),
        "loaded for the parameter study",
    )?;
    Ok(out)
}

/// The depth of a tyre's mass below the wheel's radius, m: the tread and
/// carcass of a 35-40 mm tyre sit about 2 cm inside the outer radius.
pub const TYRE_DEPTH_M: f64 = 0.02;

/// `set` with the front wheel's spin inertia multiplied by `factor` as a
/// heavier tyre does it: a ring of mass at the tyre (the radius less
/// [`TYRE_DEPTH_M`]), which adds half its spin inertia to the wheel's
/// diametral inertia and its mass to the wheel.
///
/// # Errors
/// When the set has no front wheel.
pub fn heavier_front_tyre(set: &ParamSet, factor: f64) -> Result<ParamSet, ParamError> {
    let get = |k: &str, u| set.get(&format!("front_wheel.{k}"), u);
    let radius = get("radius", Unit::Length)?;
    let added = (factor - 1.0) * get("inertia_yy", Unit::Inertia)?;
    let ring_kg = added / (radius - TYRE_DEPTH_M).powi(2);
    let mut out = set.clone();
    let why = format!("front tyre's spin inertia x{factor}: a ring of {ring_kg:.2} kg at the tyre");
    for (k, add, unit) in [
        ("inertia_yy", added, Unit::Inertia),
        ("inertia_xx", 0.5 * added, Unit::Inertia),
        ("mass", ring_kg, Unit::Mass),
    ] {
        let key = format!("front_wheel.{k}");
        let factor = set
            .quantity(&key)
            .and_then(|q| unit.factor(&q.unit))
            .ok_or_else(|| set.error(&key, Problem::Unknown))?;
        out.set_value(&key, (set.get(&key, unit)? + add) / factor, &why)?;
    }
    Ok(out)
}

/// The rider's bodies of a set: the upper body, and the legs if the file
/// keeps them apart from the frame.
fn rider_sections(set: &ParamSet) -> Vec<&'static str> {
    let mut s = vec!["torso"];
    for legs in ["rider_legs", "seated_legs"] {
        if set.quantity(&format!("{legs}.mass")).is_some() {
            s.push(legs);
        }
    }
    s
}

/// `set` with the whole rider on the hinge: `[rider_legs]` (rigid with
/// the frame) become `[seated_legs]`, which the model puts on the hinge with
/// the upper body, so the rider rolls as one on the hip's spring and
/// damper, now the lateral firmness of the rider's seat on the saddle (the
/// element the paper's section 4.2 proposes for a relaxed rider).
///
/// # Errors
/// When the set has no `[rider_legs]`.
pub fn rider_on_saddle(set: &ParamSet) -> Result<ParamSet, ParamError> {
    Body::from_set(set, "rider_legs")?;
    let mut out = set.clone();
    let legs: Vec<(String, Quantity)> = set
        .iter()
        .filter_map(|(k, q)| {
            k.strip_prefix("rider_legs.")
                .map(|key| (key.to_owned(), q.clone()))
        })
        .collect();
    out.remove_section("rider_legs");
    for (key, mut q) in legs {
        q.source = format!("{} (seated on the saddle hinge)", q.source);
        out.insert(&format!("seated_legs.{key}"), q);
    }
    Ok(out)
}

/// The rider's mass in `set`, kg: the upper body and the legs (a file
/// without `[rider_legs]` has them in the frame and gives the upper body).
///
/// # Errors
/// When the set has no rider.
pub fn rider_mass_kg(set: &ParamSet) -> Result<f64, ParamError> {
    rider_sections(set)
        .into_iter()
        .map(|s| set.get(&format!("{s}.mass"), Unit::Mass))
        .sum()
}

/// `set` with its rider scaled to `kg` (each rider body's mass and
/// inertias in proportion, mass centres kept: a lighter rider of the same
/// build and position). Needs `[rider_legs]` (or `[seated_legs]`) to scale
/// the whole rider.
///
/// # Errors
/// When the set has no `[rider_legs]` or no rider.
pub fn rider_of_mass(set: &ParamSet, kg: f64) -> Result<ParamSet, ParamError> {
    if rider_sections(set).len() < 2 {
        return Err(set.error(
            "rider_legs",
            Problem::Missing("rider-mass variation (the legs apart from the frame)"),
        ));
    }
    let k = kg / rider_mass_kg(set)?;
    let mut out = set.clone();
    for section in rider_sections(set) {
        let b = Body::from_set(set, section)?;
        let b = Body {
            mass: k * b.mass,
            inertia_xx: k * b.inertia_xx,
            inertia_xz: k * b.inertia_xz,
            inertia_yy: k * b.inertia_yy,
            inertia_zz: k * b.inertia_zz,
            ..b
        };
        put(&mut out, section, &b, &format!("rider scaled to {kg} kg"))?;
    }
    Ok(out)
}

/// `set` with the rider's bodies moved forward by `dx` m.
///
/// # Errors
/// When the set has no rider.
pub fn rider_moved(set: &ParamSet, dx: f64) -> Result<ParamSet, ParamError> {
    let mut out = set.clone();
    for section in rider_sections(set) {
        let mut b = Body::from_set(set, section)?;
        b.x += dx;
        put(
            &mut out,
            section,
            &b,
            &format!("rider moved {dx} m forward"),
        )?;
    }
    Ok(out)
}

/// `set` with the steer axis tilted `delta_deg` further from vertical
/// (the paper's steering axis angle increased), the fork offset
/// `r sin(lambda) - c cos(lambda)` and the wheelbase kept: the ground trail
/// follows, and the front frame and fork turn with the axis about the front
/// axle (their mass centres and inertias rotated), the steering head kept
/// at its height.
///
/// # Errors
/// When the set is not a wobble set.
pub fn head_angle(set: &ParamSet, delta_deg: f64) -> Result<ParamSet, ParamError> {
    let lambda = set.get("geometry.steer_axis_tilt", Unit::Angle)?;
    let trail = set.get("geometry.trail", Unit::Length)?;
    let (r, w) = (
        set.get("front_wheel.radius", Unit::Length)?,
        set.get("geometry.wheelbase", Unit::Length)?,
    );
    let offset = r * lambda.sin() - trail * lambda.cos();
    let d = delta_deg.to_radians();
    let lambda1 = lambda + d;
    let trail1 = (r * lambda1.sin() - offset) / lambda1.cos();
    let mut out = set.clone();
    let why = format!("steer axis {delta_deg:+} deg, fork offset and wheelbase kept");
    let factor = |key: &str, unit: Unit| {
        set.quantity(key)
            .and_then(|q| unit.factor(&q.unit))
            .ok_or_else(|| set.error(key, Problem::Unknown))
    };
    out.set_value(
        "geometry.steer_axis_tilt",
        lambda1 / factor("geometry.steer_axis_tilt", Unit::Angle)?,
        &why,
    )?;
    out.set_value(
        "geometry.trail",
        trail1 / factor("geometry.trail", Unit::Length)?,
        &why,
    )?;
    // A point's offset from the axle turns so that the axis direction
    // (sin lambda, cos lambda) becomes (sin lambda1, cos lambda1).
    let (s, c) = d.sin_cos();
    for section in ["front_frame", "fork"] {
        let b = Body::from_set(set, section)?;
        let (dx, dz) = (b.x - w, b.z + r);
        let (xx, xz, zz) = (b.inertia_xx, b.inertia_xz, b.inertia_zz);
        // R I R^T with R = [[c, s], [-s, c]] on (x, z).
        let turned = Body {
            x: w + dx * c + dz * s,
            z: -r - dx * s + dz * c,
            inertia_xx: c * c * xx + 2.0 * c * s * xz + s * s * zz,
            inertia_xz: -c * s * xx + (c * c - s * s) * xz + c * s * zz,
            inertia_zz: s * s * xx - 2.0 * c * s * xz + c * c * zz,
            ..b
        };
        put(&mut out, section, &turned, &why)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    fn bicycle() -> ParamSet {
        ParamSet::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("params/paper-test-bicycle.toml"),
        )
        .unwrap()
    }

    /// The fork offset `r sin(lambda) - c cos(lambda)` is kept: with
    /// r = 0.344 m, lambda 19 deg and c 74.985 mm it is 40.9 mm; at 22 deg
    /// the normal trail is 0.344 sin 22 - 0.0409 = 88.0 mm, 94.9 mm on the
    /// ground.
    #[test]
    fn a_slacker_head_keeps_the_fork_offset_and_lengthens_the_trail() {
        let set = bicycle();
        let slack = head_angle(&set, 3.0).unwrap();
        let tilt = slack.get("geometry.steer_axis_tilt", Unit::Angle).unwrap();
        assert!((tilt.to_degrees() - 22.0).abs() < 1e-9);
        let trail = slack.get("geometry.trail", Unit::Length).unwrap();
        let r = 0.344;
        let offset = r * 19f64.to_radians().sin() - 0.074_985_3 * 19f64.to_radians().cos();
        let want = (r * 22f64.to_radians().sin() - offset) / 22f64.to_radians().cos();
        assert!((trail - want).abs() < 1e-6, "{trail} against {want}");
        assert!((trail - 0.0949).abs() < 5e-4, "{trail}");
        // The fork's mass centre stays as far from the axle as before.
        let dist = |s: &ParamSet| {
            let b = Body::from_set(s, "fork").unwrap();
            ((b.x - 1.095).powi(2) + (b.z + r).powi(2)).sqrt()
        };
        assert!((dist(&set) - dist(&slack)).abs() < 1e-12);
        // And an inertia tensor's trace is unchanged by the turn.
        let trace = |s: &ParamSet| {
            let b = Body::from_set(s, "front_frame").unwrap();
            b.inertia_xx + b.inertia_zz
        };
        assert!((trace(&set) - trace(&slack)).abs() < 1e-12);
    }

    /// Half the rider's mass halves each rider body's mass and inertias
    /// and leaves their mass centres and the bicycle alone.
    #[test]
    fn the_rider_mass_key_scales_the_whole_rider() {
        let set = bicycle();
        let half = scaled_key(&set, RIDER_MASS, 0.5).unwrap();
        let m = rider_mass_kg(&set).unwrap();
        assert!((rider_mass_kg(&half).unwrap() - 0.5 * m).abs() < 1e-9);
        for (key, q) in set.iter() {
            let got = half.value(key).unwrap();
            let rider = key.starts_with("torso.") || key.starts_with("rider_legs.");
            let scales = rider && (key.ends_with("mass") || key.contains("inertia"));
            let want = if scales { 0.5 * q.value } else { q.value };
            assert!((got - want).abs() <= 1e-12 * want.abs().max(1.0), "{key}");
        }
        let stiff = scaled_key(&set, "hip.stiffness", 2.0).unwrap();
        assert_eq!(
            stiff.value("hip.stiffness").unwrap(),
            2.0 * set.value("hip.stiffness").unwrap()
        );
        assert!(scaled_key(&set, "hip.nothing", 2.0).is_err());
    }

    /// Doubling a spin inertia of 0.13 kg m^2 on a 0.344 m wheel adds a
    /// ring of 0.13 / 0.324^2 = 1.238 kg, and 0.065 to the diametral inertia.
    #[test]
    fn a_heavier_tyre_is_a_ring_at_the_tyre() {
        let mut set = bicycle();
        set.set_value("front_wheel.inertia_yy", 0.13, "test")
            .unwrap();
        let heavy = heavier_front_tyre(&set, 2.0).unwrap();
        let d = |k: &str| heavy.value(k).unwrap() - set.value(k).unwrap();
        assert!((d("front_wheel.inertia_yy") - 0.13).abs() < 1e-12);
        assert!((d("front_wheel.inertia_xx") - 0.065).abs() < 1e-12);
        assert!((d("front_wheel.mass") - 0.13 / 0.324f64.powi(2)).abs() < 1e-12);
        assert!((d("front_wheel.mass") - 1.238).abs() < 1e-3);
    }

    #[test]
    fn the_rider_on_the_saddle_keeps_the_riders_mass() {
        let set = bicycle();
        let m = rider_mass_kg(&set).unwrap();
        let saddle = rider_on_saddle(&set).unwrap();
        assert!(saddle.quantity("rider_legs.mass").is_none());
        assert_eq!(
            saddle.value("seated_legs.mass").unwrap(),
            set.value("rider_legs.mass").unwrap()
        );
        assert!((rider_mass_kg(&saddle).unwrap() - m).abs() < 1e-9);
        // The model seats the legs on the hinge: the upper body carries them,
        // the frame does not, and the Whipple bicycle of both (everything
        // lumped) is the same.
        let (a, b) = (
            crate::wobble::WobbleParams::from_set(&set).unwrap(),
            crate::wobble::WobbleParams::from_set(&saddle).unwrap(),
        );
        let legs = set.get("rider_legs.mass", Unit::Mass).unwrap();
        assert!((b.torso.mass - a.torso.mass - legs).abs() < 1e-9);
        assert!((a.rear_frame.mass - b.rear_frame.mass - legs).abs() < 1e-9);
        let (wa, wb) = (a.to_benchmark(), b.to_benchmark());
        assert!((wa.rear_frame.mass - wb.rear_frame.mass).abs() < 1e-9);
        assert!((wa.rear_frame.inertia_xx - wb.rear_frame.inertia_xx).abs() < 1e-9);
        assert!((wa.rear_frame.inertia_xz - wb.rear_frame.inertia_xz).abs() < 1e-9);
        // The light rider of a seated set scales the legs on the hinge too.
        let light = rider_of_mass(&saddle, 55.0).unwrap();
        assert!((rider_mass_kg(&light).unwrap() - 55.0).abs() < 1e-9);
        // The frame's mass is unchanged, so the bicycle weighs the same.
        assert_eq!(
            saddle.value("rear_frame.mass").unwrap(),
            set.value("rear_frame.mass").unwrap()
        );
    }

    #[test]
    fn a_load_moves_the_mass_centre_towards_it() {
        let set = bicycle();
        let b0 = Body::from_set(&set, "rear_frame").unwrap();
        let l = loaded(&set, "rear_frame", 10.0, -0.05, -0.75).unwrap();
        let b1 = Body::from_set(&l, "rear_frame").unwrap();
        assert!((b1.mass - b0.mass - 10.0).abs() < 1e-9);
        let want_x = (b0.mass * b0.x - 0.5) / (b0.mass + 10.0);
        assert!((b1.x - want_x).abs() < 1e-12);
        assert!(b1.inertia_xx > b0.inertia_xx);
    }
}
