//! Writes a simulated weave kick campaign (`corpus::simulated::weave`) as
//! card logs: `cargo run -p wobble-hil --example weave_campaign -- DIR
//! [BICYCLE] [SEED]`, then `wobblog margin --mode weave DIR`.

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .ok_or("usage: weave_campaign DIR [BICYCLE] [SEED]")?;
    let bicycle = args.next().unwrap_or_else(|| "Benchmark".into());
    let seed = args
        .next()
        .map_or(Ok(700), |s| s.parse())
        .map_err(|e| format!("seed: {e}"))?;
    let plan = wobble_hil::corpus::simulated::weave::Plan::default();
    let c = wobble_hil::corpus::simulated::weave::simulate(&bicycle, &plan, seed)?;
    let logs = c.write(std::path::Path::new(&dir))?;
    println!(
        "{} logs of {bicycle} (weave speed {:.3} m/s) in {dir}",
        logs.len(),
        c.weave_speed_mps
    );
    Ok(())
}
