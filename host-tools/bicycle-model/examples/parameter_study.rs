//! One parameter of a wobble-model file scaled by several factors: the
//! wobble speed, the wobble frequency at onset and at 2 and 14 m/s, for
//! each factor (the parameter study of `host-tools/docs/model.md`).
//!
//! `cargo run --release -p wobble-model --example parameter_study -- PARAMS KEY F1,F2,...`

use std::path::Path;
use std::process::ExitCode;

use wobble_model::{critical_speeds, Mode, Model, ParamSet, Sweep};

fn study(path: &str, key: &str, factors: &str) -> Result<(), String> {
    let base = ParamSet::load(Path::new(path)).map_err(|e| e.to_string())?;
    let value = base.value(key).map_err(|e| e.to_string())?;
    let speeds: Vec<f64> = (0..=140).map(|i| f64::from(i) * 0.1).collect();
    let hz = |w: f64| w / std::f64::consts::TAU;
    println!("factor,{key},wobble_speed_mps,onset_hz,hz_at_2_mps,hz_at_14_mps");
    for f in factors.split(',') {
        let factor: f64 = f.parse().map_err(|_| format!("not a factor: {f}"))?;
        let mut set = base.clone();
        set.set_value(key, value * factor, "parameter study")
            .map_err(|e| e.to_string())?;
        let model = Model::from_set(&set).map_err(|e| e.to_string())?;
        let sweep = Sweep::run(&model, &speeds, |_| {}).map_err(|e| e.to_string())?;
        let wobble = sweep.upper(Mode::Wobble).ok_or("no wobble mode")?;
        let onset = critical_speeds(&model, &sweep)
            .into_iter()
            .find(|c| c.mode == Mode::Wobble && c.unstable_above);
        let (speed, at_onset) = onset.map_or((String::new(), String::new()), |c| {
            (
                format!("{:.2}", c.speed_mps),
                format!("{:.2}", hz(c.im_rad_per_s)),
            )
        });
        println!(
            "{factor},{:.6},{speed},{at_onset},{:.2},{:.2}",
            value * factor,
            hz(wobble.values[20].im),
            hz(wobble.values[140].im)
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, key, factors] = args.as_slice() else {
        eprintln!("usage: parameter_study PARAMS KEY F1,F2,...");
        return ExitCode::from(2);
    };
    match study(path, key, factors) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("parameter_study: {path}: {e}");
            ExitCode::FAILURE
        }
    }
}
