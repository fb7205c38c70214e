//! Runs the firefly optimiser on the classic benchmark functions and prints
//! one JSON document with every run (used by `scripts/compare_niapy.py`).
//!
//! ```text
//! cargo run --release -p mbd-firefly --example benchmark_functions -- \
//!     --functions sphere,rastrigin --dims 2,10 --seeds 0-19 \
//!     --evaluations 30000 [--generations 1000] [--population 60] \
//!     [--alpha 0.7] [--decay 0.97] [--gamma 1] [--beta0 1] \
//!     [--variant snapshot|classic|classic-sweep] [--distance normalized|raw] \
//!     [--parallel]
//! ```
//!
//! A median / worst summary per function and dimension goes to stderr.

use std::time::Instant;

use mbd_firefly::{
    testfns, Bounds, DistanceScaling, Firefly, FireflySettings, Termination, Variant,
};
use serde_json::{json, Value};

struct Args {
    functions: Vec<String>,
    dims: Vec<usize>,
    seeds: Vec<u64>,
    settings: FireflySettings,
    termination: Termination,
    parallel: bool,
}

fn parse_list<T: std::str::FromStr>(s: &str) -> Result<Vec<T>, String> {
    s.split(',')
        .map(|p| {
            p.trim()
                .parse::<T>()
                .map_err(|_| format!("bad list item `{p}`"))
        })
        .collect()
}

fn parse_seeds(s: &str) -> Result<Vec<u64>, String> {
    if let Some((a, b)) = s.split_once('-') {
        let a: u64 = a.parse().map_err(|_| format!("bad seed range `{s}`"))?;
        let b: u64 = b.parse().map_err(|_| format!("bad seed range `{s}`"))?;
        Ok((a..=b).collect())
    } else {
        parse_list(s)
    }
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        functions: testfns::ALL.iter().map(|t| t.name.to_string()).collect(),
        dims: vec![2, 10],
        seeds: (0..20).collect(),
        settings: FireflySettings::default(),
        termination: Termination::none(),
        parallel: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        if flag == "--parallel" {
            a.parallel = true;
            continue;
        }
        let v = it
            .next()
            .ok_or_else(|| format!("missing value after {flag}"))?;
        let num = |v: &str| v.parse::<f64>().map_err(|_| format!("bad number `{v}`"));
        let int = |v: &str| v.parse::<u64>().map_err(|_| format!("bad integer `{v}`"));
        match flag.as_str() {
            "--functions" => a.functions = parse_list(&v)?,
            "--dims" => a.dims = parse_list(&v)?,
            "--seeds" => a.seeds = parse_seeds(&v)?,
            "--generations" => a.termination.max_generations = Some(int(&v)?),
            "--evaluations" => a.termination.max_evaluations = Some(int(&v)?),
            "--target" => a.termination.target = Some(num(&v)?),
            "--population" => a.settings.population = int(&v)? as usize,
            "--alpha" => a.settings.alpha = num(&v)?,
            "--decay" => a.settings.alpha_decay = num(&v)?,
            "--gamma" => a.settings.gamma = num(&v)?,
            "--beta0" => a.settings.beta0 = num(&v)?,
            "--variant" => {
                a.settings.variant = match v.as_str() {
                    "snapshot" => Variant::Snapshot,
                    "classic" => Variant::Classic,
                    "classic-sweep" => Variant::ClassicSweep,
                    _ => return Err(format!("unknown variant `{v}`")),
                }
            }
            "--distance" => {
                a.settings.distance = match v.as_str() {
                    "normalized" => DistanceScaling::Normalized,
                    "raw" => DistanceScaling::Raw,
                    _ => return Err(format!("unknown distance `{v}`")),
                }
            }
            _ => return Err(format!("unknown flag {flag}")),
        }
    }
    if a.termination.max_generations.is_none() && a.termination.max_evaluations.is_none() {
        a.termination.max_generations = Some(1000);
    }
    Ok(a)
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    let mut runs: Vec<Value> = Vec::new();
    for name in &args.functions {
        let Some(tf) = testfns::by_name(name) else {
            eprintln!("error: unknown function `{name}`");
            std::process::exit(2);
        };
        for &d in &args.dims {
            let mut finals = Vec::new();
            for &seed in &args.seeds {
                let bounds = match Bounds::cube(d, tf.lo, tf.hi) {
                    Ok(b) => b,
                    Err(e) => {
                        eprintln!("error: {e}");
                        std::process::exit(2);
                    }
                };
                let mut run = Firefly::new(bounds)
                    .settings(args.settings.clone().seed(seed))
                    .termination(args.termination.clone());
                let f = tf.f;
                let start = Instant::now();
                let res = if args.parallel {
                    run.minimize_parallel(&f)
                } else {
                    run.minimize(&mut { f })
                };
                let secs = start.elapsed().as_secs_f64();
                match res {
                    Ok(r) => {
                        finals.push(r.best_f);
                        runs.push(json!({
                            "function": tf.name,
                            "dim": d,
                            "lo": tf.lo,
                            "hi": tf.hi,
                            "seed": seed,
                            "best_f": r.best_f,
                            "evaluations": r.evaluations,
                            "generations": r.generations,
                            "stop_reason": format!("{:?}", r.stop_reason),
                            "seconds": secs,
                        }));
                    }
                    Err(e) => {
                        eprintln!("error: {e}");
                        std::process::exit(2);
                    }
                }
            }
            finals.sort_by(f64::total_cmp);
            if let (Some(worst), false) = (finals.last(), finals.is_empty()) {
                let median = finals[finals.len() / 2];
                eprintln!(
                    "{:<11} d={:<3} median {:>11.4e}  worst {:>11.4e}  ({} seeds)",
                    tf.name,
                    d,
                    median,
                    worst,
                    finals.len()
                );
            }
        }
    }
    let doc = json!({
        "settings": {
            "population": args.settings.population,
            "alpha": args.settings.alpha,
            "alpha_decay": args.settings.alpha_decay,
            "gamma": args.settings.gamma,
            "beta0": args.settings.beta0,
            "variant": format!("{:?}", args.settings.variant),
            "distance": format!("{:?}", args.settings.distance),
            "max_generations": args.termination.max_generations,
            "max_evaluations": args.termination.max_evaluations,
        },
        "runs": runs,
    });
    println!("{doc}");
}
