//! Identifies a bicycle's uncertain parameters to the seed paper's claims
//! (`wobble_model::paper`): a seeded random search inside stated bounds,
//! then a (1+1) evolution strategy from the best starts, for each
//! structural variant of the spec; the best bicycle of the best variant is
//! written with a source note per identified value, and its light-rider
//! version beside it.
//!
//! `cargo run --release -p wobble-model --example identify -- SPEC`
//!
//! The spec (`identify/paper-test-bicycle.toml`) names the start file (the
//! bodies and geometry, which are not identified), the outputs, the seed
//! and budget, every free parameter with its bounds and their source, and
//! the variants, and the readings of the paper: starts (values set on the
//! random search's best before a local search of their own) whose
//! bicycles are written as candidates beside the outputs and compete with
//! the variants' best for the bundled bicycle. The score of a
//! bicycle is ten times the summed misses of the measured figures (each in
//! half-widths of its band, at most 3) plus the number of directional
//! claims it does not reproduce: measured figures first, then as many
//! directions as the model reaches.
//!
//! Written here rather than taken from an optimisation crate: the score is
//! a count of claims (piecewise constant), so gradient and simplex methods
//! stall on its plateaus; a random search with a step-adapted local search
//! is the standard remedy and a few lines.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use serde::Deserialize;
use wobble_model::paper::{
    variation, Kind, Study, Verdict, CLAIMS, LIGHT_RIDER_KG, TABLE_STEP_MPS,
};
use wobble_model::params::to_toml;
use wobble_model::{ParamSet, Quantity};

/// Sweep step of the search, m/s (the table's finer step checks the result).
const SEARCH_STEP_MPS: f64 = 0.25;
/// Starts kept from the random search for the local search.
const STARTS: usize = 6;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    name: String,
    start: PathBuf,
    output: PathBuf,
    light_output: PathBuf,
    seed: u64,
    samples: usize,
    refine: usize,
    free: Vec<Free>,
    variant: Vec<Variant>,
    #[serde(default)]
    reading: Vec<Reading>,
}

/// A start for the local search that the random search is unlikely to
/// draw: the random search's best with some values set as a reading of the
/// paper suggests, refined for its own budget. Its bicycle is a candidate,
/// written to its own file beside the spec's outputs, and kept as the
/// bundled bicycle if it scores better than every variant's best.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Reading {
    name: String,
    about: String,
    output: PathBuf,
    /// The variants it is tried on.
    variants: Vec<String>,
    /// Local-search steps from it.
    refine: usize,
    /// The values set, in the free parameters' units.
    set: BTreeMap<String, f64>,
}

#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
struct Free {
    key: String,
    lo: f64,
    hi: f64,
    unit: String,
    #[serde(default)]
    log: bool,
    source: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Variant {
    name: String,
    about: String,
    #[serde(default)]
    fixed: BTreeMap<String, Fixed>,
    /// The whole rider on the hip's hinge, as on a saddle
    /// (`variation::rider_on_saddle`).
    #[serde(default)]
    rider_on_saddle: bool,
    #[serde(default)]
    free: Vec<Free>,
}

#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
struct Fixed {
    value: f64,
    unit: String,
    source: String,
}

impl Free {
    /// The value at `t` in [0, 1] of its range.
    fn at(&self, t: f64) -> f64 {
        if self.log {
            (self.lo.ln() + t * (self.hi.ln() - self.lo.ln())).exp()
        } else {
            self.lo + t * (self.hi - self.lo)
        }
    }

    /// Where `value` lies in [0, 1] of its range (clamped).
    fn t_of(&self, value: f64) -> f64 {
        let t = if self.log {
            (value.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())
        } else {
            (value - self.lo) / (self.hi - self.lo)
        };
        t.clamp(0.0, 1.0)
    }
}

/// `x` to six significant figures, as the files write it (and as it is
/// scored).
fn six_figures(x: f64) -> f64 {
    format!("{x:.5e}").parse().unwrap_or(x)
}

/// A scored candidate: its point in the unit cube and its verdicts.
#[derive(Clone)]
struct Scored {
    t: Vec<f64>,
    score: f64,
}

struct Problem<'a> {
    base: ParamSet,
    free: Vec<Free>,
    spec: &'a Spec,
}

impl Problem<'_> {
    fn set_of(&self, t: &[f64]) -> ParamSet {
        let mut set = self.base.clone();
        for (f, &x) in self.free.iter().zip(t) {
            set.insert(
                &f.key,
                Quantity {
                    value: six_figures(f.at(x)),
                    unit: f.unit.clone(),
                    source: format!(
                        "identified to the seed paper's claims (examples/identify.rs, {}): within {}-{} {}, {}",
                        self.spec.name, f.lo, f.hi, f.unit, f.source
                    ),
                },
            );
        }
        set
    }

    fn verdicts(&self, set: &ParamSet, step: f64) -> Option<Vec<Verdict>> {
        let mut study = Study::new(set, LIGHT_RIDER_KG, step);
        CLAIMS.iter().map(|c| c.check(&mut study).ok()).collect()
    }

    fn score(&self, t: &[f64]) -> f64 {
        self.verdicts(&self.set_of(t), SEARCH_STEP_MPS)
            .map_or(f64::INFINITY, |v| score(&v))
    }
}

fn score(v: &[Verdict]) -> f64 {
    CLAIMS
        .iter()
        .zip(v)
        .map(|(c, v)| match c.kind {
            // A measured figure missed costs more than three directions.
            Kind::Measured if !v.agrees => 3.0 + 10.0 * v.miss.min(3.0),
            Kind::Measured => 0.0,
            Kind::Direction => f64::from(u8::from(!v.agrees)),
        })
        .sum()
}

/// The best of the random starts, and each reading's refined bicycle.
fn search<'a>(
    p: &Problem<'a>,
    rng: &mut Xoshiro256PlusPlus,
    name: &str,
) -> (Scored, Vec<(&'a Reading, Scored)>) {
    let n = p.free.len();
    let mut pool: Vec<Scored> = (0..p.spec.samples)
        .map(|i| {
            let t: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
            let score = p.score(&t);
            if (i + 1) % 500 == 0 {
                eprintln!("  {name}: sampled {} of {}", i + 1, p.spec.samples);
            }
            Scored { t, score }
        })
        .collect();
    pool.sort_by(|a, b| a.score.total_cmp(&b.score));
    pool.truncate(STARTS);
    let per_start = p.spec.refine / STARTS;
    let mut best = pool[0].clone();
    // The paper's readings start from the random search's best.
    let from = best.t.clone();
    for (k, start) in pool.into_iter().enumerate() {
        let cur = refine(p, rng, start, per_start);
        eprintln!("  {name}: start {}, score {:.2}", k + 1, cur.score);
        if cur.score < best.score {
            best = cur;
        }
    }
    let readings = p
        .spec
        .reading
        .iter()
        .filter(|r| r.variants.iter().any(|v| v == name))
        .map(|r| {
            eprintln!("  {name}: {}: {}", r.name, r.about);
            let mut t = from.clone();
            for (f, x) in p.free.iter().zip(&mut t) {
                if let Some(&v) = r.set.get(&f.key) {
                    *x = f.t_of(v);
                }
            }
            let score = p.score(&t);
            let cur = refine(p, rng, Scored { t, score }, r.refine);
            eprintln!("  {name}: {}, score {:.2}", r.name, cur.score);
            (r, cur)
        })
        .collect();
    (best, readings)
}

/// A (1+1) evolution strategy with the 1/5 success rule from `start`,
/// `steps` candidates long; a candidate as good as the current one is
/// taken (the score is flat between claims: the search walks its plateaus).
fn refine(p: &Problem, rng: &mut Xoshiro256PlusPlus, start: Scored, steps: usize) -> Scored {
    let mut cur = start;
    let mut step = 0.1;
    for _ in 0..steps {
        let t: Vec<f64> = cur
            .t
            .iter()
            .map(|&x| {
                // A normal step by Box-Muller, kept inside the cube.
                let (u1, u2): (f64, f64) = (rng.random(), rng.random());
                let z = (-2.0 * (1.0 - u1).ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
                (x + step * z).clamp(0.0, 1.0)
            })
            .collect();
        let score = p.score(&t);
        if score <= cur.score {
            cur = Scored { t, score };
            step = (step * 1.5).min(0.3);
        } else {
            step = (step * 0.9).max(0.005);
        }
    }
    cur
}

/// One variant's identification.
struct Outcome {
    /// The best bicycle's score.
    score: f64,
    variant: String,
    set: ParamSet,
    /// The verdicts, in words.
    report: String,
    /// The readings' bicycles, where they go, their labels and scores.
    candidates: Vec<Candidate>,
}

/// A reading's bicycle.
struct Candidate {
    output: PathBuf,
    label: String,
    score: f64,
    set: ParamSet,
}

/// The best bicycle of one variant, and its readings' candidates.
fn identify_variant(spec: &Spec, start: &ParamSet, v: &Variant) -> Result<Outcome, String> {
    eprintln!("variant {}: {}", v.name, v.about);
    let mut base = if v.rider_on_saddle {
        variation::rider_on_saddle(start).map_err(|e| e.to_string())?
    } else {
        start.clone()
    };
    for (key, f) in &v.fixed {
        base.insert(
            key,
            Quantity {
                value: f.value,
                unit: f.unit.clone(),
                source: f.source.clone(),
            },
        );
    }
    let mut free = spec.free.clone();
    free.extend(v.free.iter().cloned());
    for s in &spec.reading {
        if let Some(key) = s.set.keys().find(|k| !free.iter().any(|f| &f.key == *k)) {
            return Err(format!(
                "reading {:?} sets {key}, which is not a free parameter",
                s.name
            ));
        }
    }
    let p = Problem { base, free, spec };
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(spec.seed);
    let (best, readings) = search(&p, &mut rng, &v.name);
    let (score, set, mut report) = report(&p, &format!("variant {}", v.name), &best.t)?;
    let mut candidates = Vec::new();
    for (r, cur) in readings {
        let label = format!("variant {}, {}", v.name, r.name);
        let (score, set, text) = self::report(&p, &label, &cur.t)?;
        report.push_str(&text);
        candidates.push(Candidate {
            output: r.output.clone(),
            label,
            score,
            set,
        });
    }
    Ok(Outcome {
        score,
        variant: format!("variant {}", v.name),
        set,
        report,
        candidates,
    })
}

/// The table-grid verdicts of the bicycle at `t`: its score, set and
/// report.
fn report(p: &Problem, label: &str, t: &[f64]) -> Result<(f64, ParamSet, String), String> {
    let set = p.set_of(t);
    let verdicts = p
        .verdicts(&set, TABLE_STEP_MPS)
        .ok_or("the best bicycle cannot be evaluated on the table's grid")?;
    let s = score(&verdicts);
    let agree = |k: Kind| {
        CLAIMS
            .iter()
            .zip(&verdicts)
            .filter(|(c, v)| c.kind == k && v.agrees)
            .count()
    };
    let total = |k: Kind| CLAIMS.iter().filter(|c| c.kind == k).count();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{label}: score {s:.2}; measured {} of {}, directions {} of {}",
        agree(Kind::Measured),
        total(Kind::Measured),
        agree(Kind::Direction),
        total(Kind::Direction)
    );
    for (f, &x) in p.free.iter().zip(t) {
        let _ = writeln!(out, "  {} = {:.6} {}", f.key, f.at(x), f.unit);
    }
    for (c, v) in CLAIMS.iter().zip(&verdicts) {
        let _ = writeln!(
            out,
            "  {:<5} {:<3} {}",
            c.id,
            if v.agrees { "yes" } else { "no" },
            v.figures
        );
    }
    Ok((s, set, out))
}

fn write_whole(path: &Path, text: &str) -> Result<(), String> {
    let tmp = path.with_extension("toml.tmp");
    std::fs::write(&tmp, text).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}

fn run(spec_path: &Path) -> Result<(), String> {
    let text =
        std::fs::read_to_string(spec_path).map_err(|e| format!("{}: {e}", spec_path.display()))?;
    let spec: Spec = toml::from_str(&text).map_err(|e| format!("{}: {e}", spec_path.display()))?;
    let dir = spec_path.parent().unwrap_or(Path::new("."));
    let start = ParamSet::load(&dir.join(&spec.start)).map_err(|e| e.to_string())?;
    // Each variant on its own thread, with its own seeded generator: the
    // result does not depend on the scheduling.
    let outcomes: Vec<Result<Outcome, String>> = std::thread::scope(|scope| {
        let handles: Vec<_> = spec
            .variant
            .iter()
            .map(|v| scope.spawn(|| identify_variant(&spec, &start, v)))
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err("a variant's search panicked".into()))
            })
            .collect()
    });
    // The variants' best first: a reading must score better to be kept.
    let mut results = Vec::new();
    let mut readings = Vec::new();
    for o in outcomes {
        let o = o?;
        print!("{}", o.report);
        results.push((o.score, o.variant, o.set));
        readings.extend(o.candidates);
    }
    for c in readings {
        let mut set = c.set.clone();
        set.name = format!(
            "Seed paper's test bicycle, 83 kg rider: {} (a candidate)",
            c.label
        );
        set.source = format!(
            "seed paper Table 1 and the bodies of scripts/derive_test_bicycle.py; uncertain parameters identified by examples/identify.rs ({}, {}) from a reading of the paper (model.md)",
            spec.name, c.label
        );
        write_whole(&dir.join(&c.output), &header(&to_toml(&set)))?;
        results.push((c.score, c.label, c.set));
    }
    let (_, name, mut best) = results
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or("the spec has no variant")?;
    println!("kept: {name}");
    best.name = format!("Seed paper's test bicycle, 83 kg rider ({name})");
    best.source = format!(
        "seed paper Table 1 and the bodies of scripts/derive_test_bicycle.py; uncertain parameters identified to the paper's claims by examples/identify.rs ({}, {name})",
        spec.name
    );
    let mut light = variation::rider_of_mass(&best, LIGHT_RIDER_KG).map_err(|e| e.to_string())?;
    light.name = format!("Seed paper's test bicycle, {LIGHT_RIDER_KG} kg rider ({name})");
    write_whole(&dir.join(&spec.output), &header(&to_toml(&best)))?;
    write_whole(&dir.join(&spec.light_output), &header(&to_toml(&light)))?;
    Ok(())
}

fn header(toml: &str) -> String {
    format!("# Written by examples/identify.rs from identify/paper-test-bicycle.toml: do not edit by hand.\n{toml}")
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [spec] = args.as_slice() else {
        eprintln!("usage: identify SPEC");
        return ExitCode::from(2);
    };
    match run(Path::new(spec)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("identify: {e}");
            ExitCode::FAILURE
        }
    }
}
