//! The margin prediction on the stress campaigns
//! (`wobble_hil::margin_stress`): per shape class, the coverage of the
//! closed 95 % intervals, how often the lower bound lies more than 5 % and
//! 10 % above the truth, how often the interval stays open, and the point
//! estimate's error; the host's (`wobblog margin`) on two scatter ranges,
//! the board's (`MarginWarning`) on the acceptance's.
//!
//! ```text
//! cargo run -p wobble-hil --release --example margin_stress -- [FIRST_SEED] [CAMPAIGNS]
//! ```
//! `BEND=MEAN:SD_CONVEX:SD_CONCAVE` sets the line's bend prior (the shape
//! `beta` of `wobblog::analysis::margin::bend`). The figures in `host-tools/docs/kick-testing.md` are from seeds 1000000
//! on (2000 campaigns per class); the defaults were chosen on seeds 0-399.

use wobble_hil::margin_stress::{board_outcomes, host_outcomes, Recipe, Shape, Tally};
use wobblog::analysis::margin::BendPrior;

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let mut number = |default: u64| -> Result<u64, String> {
        args.next().map_or(Ok(default), |a| {
            a.parse().map_err(|_| format!("{a} is not a number"))
        })
    };
    let first = number(1_000_000)?;
    let campaigns = number(2000)?;
    let prior = match std::env::var("BEND") {
        Err(_) => BendPrior::DEFAULT,
        Ok(spec) => {
            let v: Vec<f64> = spec.split(':').filter_map(|p| p.parse().ok()).collect();
            let [mean, sd_convex, sd_concave] = v[..] else {
                return Err(format!("BEND={spec} is not MEAN:SD_CONVEX:SD_CONCAVE"));
            };
            BendPrior {
                mean,
                sd_convex,
                sd_concave,
            }
        }
    };
    println!(
        "| recipe | class | closed | coverage of closed | lower > 5 % over | lower > 10 % over | \
         ride limit over | estimate within 5 % (closed) | median abs error | median closed width | false claims |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, recipe) in [
        ("scatter 0.12", Recipe::acceptance as fn(Shape) -> Recipe),
        ("scatter 0.04-0.15", Recipe::wide),
    ] {
        let mut pooled = Vec::new();
        for shape in Shape::ALL {
            let outcomes = host_outcomes(&recipe(shape), prior, first, campaigns);
            print_row(name, shape.name(), &Tally::of(&outcomes));
            if shape.beta().is_some() {
                pooled.extend(outcomes);
            }
        }
        print_row(name, "pooled (with a wobble speed)", &Tally::of(&pooled));
    }
    // The board: a straight line over its latest 24 kicks, no riding limit.
    let mut pooled = Vec::new();
    for shape in Shape::ALL {
        let outcomes = board_outcomes(&Recipe::acceptance(shape), first, campaigns);
        print_row("board, scatter 0.12", shape.name(), &Tally::of(&outcomes));
        if shape.beta().is_some() {
            pooled.extend(outcomes);
        }
    }
    print_row(
        "board, scatter 0.12",
        "pooled (with a wobble speed)",
        &Tally::of(&pooled),
    );
    Ok(())
}

fn print_row(recipe: &str, class: &str, t: &Tally) {
    let pc = |k: usize, n: usize| format!("{:.1} %", 100.0 * k as f64 / n.max(1) as f64);
    println!(
        "| {recipe} | {class} | {} | {} | {} | {} | {} | {} | {:.1} % | {:.0} % | {} |",
        pc(t.closed, t.n),
        pc(t.covered, t.closed),
        pc(t.lower_over_5, t.n),
        pc(t.lower_over_10, t.n),
        pc(t.ride_over, t.n),
        pc(t.closed_within_5, t.closed),
        100.0 * t.median_abs_error,
        100.0 * t.median_width,
        t.false_claims
    );
}
