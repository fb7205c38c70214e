//! The algorithm proper: population state and one generation of moves.
//!
//! [`Swarm`] knows nothing about stopping rules or observers; the driver
//! [`Firefly`](crate::Firefly) combines it with them. It is public for callers
//! that want to step generations by hand (and for benchmarking).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::{
    BoundaryHandling, Bounds, DistanceScaling, FireflyError, FireflySettings, GenerationRecord,
    Objective, SyncObjective, Variant,
};

mod eval;
#[cfg(test)]
mod tests;

use eval::{Evaluator, ParallelEval, SerialEval};

/// Geometry and move parameters, split from the mutable population buffers so
/// that moves can borrow both.
#[derive(Debug, Clone)]
struct Mover {
    lo: Vec<f64>,
    hi: Vec<f64>,
    width: Vec<f64>,
    /// Multiplier of coordinate differences in the distance (1 or 1/width).
    dist_scale: Vec<f64>,
    beta0: f64,
    beta_min: f64,
    gamma: f64,
    boundary: BoundaryHandling,
}

impl Mover {
    /// Moves `xi` toward `xj`: `xi += beta(r) (xj - xi) + alpha (u - 1/2) width`,
    /// then confines every coordinate to the box. Draws exactly `d` uniforms.
    #[inline]
    fn attract(&self, xi: &mut [f64], xj: &[f64], alpha: f64, rng: &mut ChaCha8Rng) {
        let mut r2 = 0.0;
        for ((a, b), s) in xi.iter().zip(xj).zip(&self.dist_scale) {
            let t = (b - a) * s;
            r2 += t * t;
        }
        let beta = (self.beta0 - self.beta_min) * (-self.gamma * r2).exp() + self.beta_min;
        let geometry = self.lo.iter().zip(&self.hi).zip(&self.width);
        for ((a, b), ((&l, &h), w)) in xi.iter_mut().zip(xj).zip(geometry) {
            let u: f64 = rng.random();
            let v = *a + beta * (b - *a) + alpha * (u - 0.5) * w;
            *a = self.confine(v, l, h);
        }
    }

    /// Pure random step `xi += alpha (u - 1/2) width`, confined. Draws `d` uniforms.
    fn walk(&self, xi: &mut [f64], alpha: f64, rng: &mut ChaCha8Rng) {
        let geometry = self.lo.iter().zip(&self.hi).zip(&self.width);
        for (a, ((&l, &h), w)) in xi.iter_mut().zip(geometry) {
            let u: f64 = rng.random();
            let v = *a + alpha * (u - 0.5) * w;
            *a = self.confine(v, l, h);
        }
    }

    /// Brings `v` back into `[l, h]` (fast path: already inside).
    #[inline(always)]
    fn confine(&self, v: f64, l: f64, h: f64) -> f64 {
        if v >= l && v <= h {
            v
        } else {
            self.outside(v, l, h)
        }
    }

    /// Slow path of [`Mover::confine`] for a value outside `[l, h]` (or NaN).
    #[cold]
    #[inline(never)]
    fn outside(&self, v: f64, l: f64, h: f64) -> f64 {
        let clamp = |v: f64| if v > h { h } else { l }; // NaN goes to `l`
        match self.boundary {
            BoundaryHandling::Clamp => clamp(v),
            BoundaryHandling::Reflect => {
                let w = h - l;
                if w <= 0.0 || !v.is_finite() {
                    return clamp(v);
                }
                let period = 2.0 * w;
                let mut t = (v - l).rem_euclid(period);
                if t > w {
                    t = period - t;
                }
                (l + t).clamp(l, h)
            }
        }
    }
}

/// Mutable row `i` and shared row `j` (`i != j`) of a row-major buffer.
fn two_rows(buf: &mut [f64], i: usize, j: usize, d: usize) -> (&mut [f64], &[f64]) {
    if i < j {
        let (a, b) = buf.split_at_mut(j * d);
        (&mut a[i * d..(i + 1) * d], &b[..d])
    } else {
        let (a, b) = buf.split_at_mut(i * d);
        (&mut b[..d], &a[j * d..(j + 1) * d])
    }
}

/// A firefly population with its random stream and bookkeeping.
///
/// Life cycle: [`Swarm::new`] places the population (supplied positions first,
/// the rest uniform in the box), [`Swarm::initialize`] evaluates it
/// (generation 0), and each [`Swarm::step`] runs one generation of the
/// configured [`Variant`]. The `*_parallel` methods use rayon: for
/// [`Variant::Snapshot`] the moves and evaluations of a generation run in
/// parallel with bit-identical results to the serial methods on any number of
/// threads; the classic variants (inherently sequential) simply run serially.
///
/// All buffers are allocated once in [`Swarm::new`]; a generation allocates
/// nothing (rayon's task bookkeeping aside).
///
/// The order of fireflies in the population is an implementation detail: the
/// snapshot variant stores them sorted by brightness after every generation.
#[derive(Debug, Clone)]
pub struct Swarm {
    n: usize,
    d: usize,
    mover: Mover,
    alpha: f64,
    last_alpha: f64,
    alpha_decay: f64,
    variant: Variant,
    walk: bool,
    /// Main stream (stream 0): initial positions and the classic variants.
    rng: ChaCha8Rng,
    /// Unused copy of the freshly seeded generator; the snapshot variant
    /// derives one stream per (generation, firefly) from it.
    stream_root: ChaCha8Rng,
    pos: Vec<f64>,
    fit: Vec<f64>,
    snap_pos: Vec<f64>,
    snap_fit: Vec<f64>,
    order: Vec<usize>,
    raw: Vec<f64>,
    best_x: Vec<f64>,
    best_f: f64,
    has_best: bool,
    initialized: bool,
    generation: u64,
    evaluations: u64,
    nan_evaluations: u64,
}

impl Swarm {
    /// Validates the input, seeds the random stream with `settings.seed` and
    /// places the population: firefly `i < initial.len()` starts at
    /// `initial[i]`, the others uniformly at random in the box (drawn in
    /// firefly order, coordinate by coordinate). Nothing is evaluated yet.
    ///
    /// # Errors
    /// Any error of [`FireflySettings::validate`];
    /// [`FireflyError::TooManyInitialPositions`],
    /// [`FireflyError::InitialPositionDimension`] or
    /// [`FireflyError::InitialPositionOutOfBounds`] for bad initial positions.
    pub fn new(
        bounds: &Bounds,
        settings: &FireflySettings,
        initial: &[Vec<f64>],
    ) -> Result<Self, FireflyError> {
        settings.validate()?;
        let n = settings.population;
        let d = bounds.dim();
        if n.checked_mul(d).is_none() {
            return Err(FireflyError::InvalidParameter {
                name: "population",
                value: n as f64,
                requirement: "such that population * dimension fits in usize",
            });
        }
        check_initial(bounds, n, initial)?;

        let lo = bounds.lo().to_vec();
        let hi = bounds.hi().to_vec();
        let width: Vec<f64> = lo.iter().zip(&hi).map(|(l, h)| h - l).collect();
        let dist_scale = match settings.distance {
            DistanceScaling::Raw => vec![1.0; d],
            DistanceScaling::Normalized => width
                .iter()
                .map(|&w| if w > 0.0 { 1.0 / w } else { 0.0 })
                .collect(),
        };
        let stream_root = ChaCha8Rng::seed_from_u64(settings.seed);
        let mut rng = stream_root.clone();
        let mut pos = vec![0.0; n * d];
        for (i, row) in pos.chunks_exact_mut(d).enumerate() {
            if let Some(x) = initial.get(i) {
                row.copy_from_slice(x);
            } else {
                for (k, v) in row.iter_mut().enumerate() {
                    let u: f64 = rng.random();
                    // `min` guards against rounding past `hi`.
                    *v = (lo[k] + u * width[k]).min(hi[k]);
                }
            }
        }
        let best_x = pos[..d].to_vec();
        Ok(Self {
            n,
            d,
            mover: Mover {
                lo,
                hi,
                width,
                dist_scale,
                beta0: settings.beta0,
                beta_min: settings.beta_min,
                gamma: settings.gamma,
                boundary: settings.boundary,
            },
            alpha: settings.alpha,
            last_alpha: settings.alpha,
            alpha_decay: settings.alpha_decay,
            variant: settings.variant,
            walk: settings.best_random_walk,
            rng,
            stream_root,
            pos,
            fit: vec![f64::INFINITY; n],
            snap_pos: vec![0.0; n * d],
            snap_fit: vec![f64::INFINITY; n],
            order: (0..n).collect(),
            raw: vec![0.0; n],
            best_x,
            best_f: f64::INFINITY,
            has_best: false,
            initialized: false,
            generation: 0,
            evaluations: 0,
            nan_evaluations: 0,
        })
    }

    /// Evaluates the initial population serially, at most `eval_limit`
    /// evaluations (`None`: no limit). Fireflies beyond the limit are left
    /// unevaluated with brightness `+inf`. Does nothing if already initialised.
    pub fn initialize<O: Objective + ?Sized>(
        &mut self,
        objective: &mut O,
        eval_limit: Option<u64>,
    ) {
        self.init_with(&mut SerialEval(objective), eval_limit);
    }

    /// As [`Swarm::initialize`], evaluating in parallel with rayon.
    pub fn initialize_parallel<O: SyncObjective + ?Sized>(
        &mut self,
        objective: &O,
        eval_limit: Option<u64>,
    ) {
        self.init_with(&mut ParallelEval(objective), eval_limit);
    }

    /// Runs one generation, calling the objective serially at most
    /// `eval_limit` times (`None`: no limit). If the limit cuts the generation
    /// short, the fireflies that were not evaluated keep their previous
    /// position and brightness. On a swarm that is not yet initialised this
    /// evaluates the initial population instead.
    pub fn step<O: Objective + ?Sized>(&mut self, objective: &mut O, eval_limit: Option<u64>) {
        self.step_with(&mut SerialEval(objective), eval_limit);
    }

    /// As [`Swarm::step`], moving and evaluating the snapshot variant's
    /// fireflies in parallel with rayon (bit-identical to [`Swarm::step`]); the
    /// classic variants run serially.
    pub fn step_parallel<O: SyncObjective + ?Sized>(
        &mut self,
        objective: &O,
        eval_limit: Option<u64>,
    ) {
        self.step_with(&mut ParallelEval(objective), eval_limit);
    }

    /// Best point found so far (the first firefly's starting position before
    /// anything was evaluated).
    pub fn best_x(&self) -> &[f64] {
        &self.best_x
    }

    /// Best value found so far (`+inf` before any finite evaluation).
    pub fn best_f(&self) -> f64 {
        self.best_f
    }

    /// Generations completed (0 after initialisation).
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Objective evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Non-finite objective values so far.
    pub fn nan_evaluations(&self) -> u64 {
        self.nan_evaluations
    }

    /// Randomisation strength the next generation will use.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Number of fireflies.
    pub fn population(&self) -> usize {
        self.n
    }

    /// Dimension of the search box.
    pub fn dim(&self) -> usize {
        self.d
    }

    /// Position of firefly `i`, or `None` if `i` is out of range.
    pub fn position(&self, i: usize) -> Option<&[f64]> {
        if i < self.n {
            Some(&self.pos[i * self.d..(i + 1) * self.d])
        } else {
            None
        }
    }

    /// Objective value of firefly `i` as used for ranking (non-finite values
    /// and unevaluated fireflies read `+inf`), or `None` if out of range.
    pub fn fitness(&self, i: usize) -> Option<f64> {
        self.fit.get(i).copied()
    }

    /// Summary of the current state (see [`GenerationRecord`]).
    pub fn record(&self) -> GenerationRecord {
        let (mut sum, mut count) = (0.0, 0u64);
        for &f in &self.fit {
            if f.is_finite() {
                sum += f;
                count += 1;
            }
        }
        GenerationRecord {
            generation: self.generation,
            best_f: self.best_f,
            mean_f: if count > 0 {
                sum / count as f64
            } else {
                f64::NAN
            },
            alpha: self.last_alpha,
            evaluations: self.evaluations,
            nan_evaluations: self.nan_evaluations,
        }
    }

    fn init_with<E: Evaluator>(&mut self, e: &mut E, eval_limit: Option<u64>) {
        if self.initialized {
            return;
        }
        self.initialized = true;
        let m = capped(self.n, eval_limit);
        let d = self.d;
        e.batch(&mut self.pos[..m * d], d, &mut self.raw[..m], |_, _| ());
        for i in 0..m {
            self.absorb(i, self.raw[i]);
        }
        self.fit[m..].fill(f64::INFINITY);
    }

    fn step_with<E: Evaluator>(&mut self, e: &mut E, eval_limit: Option<u64>) {
        if !self.initialized {
            self.init_with(e, eval_limit);
            return;
        }
        match self.variant {
            Variant::Snapshot => self.step_snapshot(e, eval_limit),
            Variant::Classic => self.step_classic(e, eval_limit, true),
            Variant::ClassicSweep => self.step_classic(e, eval_limit, false),
        }
        self.last_alpha = self.alpha;
        self.alpha *= self.alpha_decay;
        self.generation += 1;
    }

    /// Stores the value of firefly `i`'s fresh evaluation and updates the
    /// counters and the best-so-far record.
    fn absorb(&mut self, i: usize, value: f64) {
        self.evaluations += 1;
        let f = if value.is_finite() {
            value
        } else {
            self.nan_evaluations += 1;
            f64::INFINITY
        };
        self.fit[i] = f;
        if !self.has_best || f < self.best_f {
            self.has_best = true;
            self.best_f = f;
            self.best_x
                .copy_from_slice(&self.pos[i * self.d..(i + 1) * self.d]);
        }
    }

    /// Sorted snapshot generation: every firefly moves from a frozen copy with
    /// its own random stream and is evaluated; independent per firefly.
    fn step_snapshot<E: Evaluator>(&mut self, e: &mut E, eval_limit: Option<u64>) {
        let (n, d) = (self.n, self.d);
        for (k, o) in self.order.iter_mut().enumerate() {
            *o = k;
        }
        let fit = &self.fit;
        // Keys are unique (index tie-break), so the unstable sort is deterministic.
        self.order
            .sort_unstable_by(|&a, &b| fit[a].total_cmp(&fit[b]).then(a.cmp(&b)));
        for (k, &i) in self.order.iter().enumerate() {
            self.snap_pos[k * d..(k + 1) * d].copy_from_slice(&self.pos[i * d..(i + 1) * d]);
            self.snap_fit[k] = self.fit[i];
        }
        self.pos.copy_from_slice(&self.snap_pos);
        self.fit.copy_from_slice(&self.snap_fit);

        // Without the random walk, the leaders (tied with the best) do not move
        // and need no new evaluation.
        let t = if self.walk {
            0
        } else {
            let f0 = self.snap_fit[0];
            self.snap_fit.iter().take_while(|&&f| f == f0).count()
        };
        let m = t + capped(n - t, eval_limit);

        // Firefly `k` (sorted rank) draws its random numbers from its own
        // ChaCha stream `g * n + k` (g = this generation, 1-based), so its move
        // depends only on the snapshot and that stream: the moves, and the
        // evaluations, can run in any order or in parallel with identical
        // results. Stream 0 (the main stream) is never used here.
        let alpha = self.alpha;
        let stream_base = (self.generation + 1).wrapping_mul(n as u64);
        let mover = &self.mover;
        let snap_pos = &self.snap_pos;
        let snap_fit = &self.snap_fit;
        let root = &self.stream_root;
        let prepare = |offset: usize, xi: &mut [f64]| {
            let k = t + offset;
            let mut rng = root.clone();
            rng.set_stream(stream_base.wrapping_add(k as u64));
            let fk = snap_fit[k];
            let mut moved = false;
            for (xj, &fj) in snap_pos.chunks_exact(d).zip(&snap_fit[..k]) {
                if fj < fk {
                    mover.attract(xi, xj, alpha, &mut rng);
                    moved = true;
                } else {
                    break; // sorted: no brighter firefly follows
                }
            }
            if !moved {
                mover.walk(xi, alpha, &mut rng);
            }
        };
        e.batch(&mut self.pos[t * d..m * d], d, &mut self.raw[t..m], prepare);
        for k in t..m {
            self.absorb(k, self.raw[k]);
        }
    }

    /// Classic in-place double loop; `per_move` selects evaluation after every
    /// move ([`Variant::Classic`]) or after every sweep ([`Variant::ClassicSweep`]).
    fn step_classic<E: Evaluator>(&mut self, e: &mut E, eval_limit: Option<u64>, per_move: bool) {
        let (n, d) = (self.n, self.d);
        let alpha = self.alpha;
        let mut left = eval_limit;
        let exhausted = |left: Option<u64>| left == Some(0);
        'fireflies: for i in 0..n {
            let sweep_f = self.fit[i];
            let mut moved = false;
            for j in 0..n {
                if j == i {
                    continue;
                }
                let fi = if per_move { self.fit[i] } else { sweep_f };
                if self.fit[j] < fi {
                    // Each move is paid for before it is made: one evaluation
                    // per move (per_move) or one per moved firefly (sweep).
                    if (per_move || !moved) && exhausted(left) {
                        break 'fireflies;
                    }
                    let (xi, xj) = two_rows(&mut self.pos, i, j, d);
                    self.mover.attract(xi, xj, alpha, &mut self.rng);
                    moved = true;
                    if per_move {
                        self.eval_in_place(e, i, &mut left);
                    }
                }
            }
            if !moved && self.walk {
                if exhausted(left) {
                    break 'fireflies;
                }
                self.mover
                    .walk(&mut self.pos[i * d..(i + 1) * d], alpha, &mut self.rng);
                self.eval_in_place(e, i, &mut left);
            } else if moved && !per_move {
                self.eval_in_place(e, i, &mut left);
            }
        }
    }

    fn eval_in_place<E: Evaluator>(&mut self, e: &mut E, i: usize, left: &mut Option<u64>) {
        let d = self.d;
        let v = e.one(&self.pos[i * d..(i + 1) * d]);
        self.absorb(i, v);
        if let Some(l) = left.as_mut() {
            *l = l.saturating_sub(1);
        }
    }
}

/// `min(n, limit)` as a `usize`.
fn capped(n: usize, limit: Option<u64>) -> usize {
    match limit {
        Some(l) if l < n as u64 => l as usize,
        _ => n,
    }
}

fn check_initial(bounds: &Bounds, n: usize, initial: &[Vec<f64>]) -> Result<(), FireflyError> {
    if initial.len() > n {
        return Err(FireflyError::TooManyInitialPositions {
            given: initial.len(),
            population: n,
        });
    }
    let d = bounds.dim();
    for (index, x) in initial.iter().enumerate() {
        if x.len() != d {
            return Err(FireflyError::InitialPositionDimension {
                index,
                expected: d,
                found: x.len(),
            });
        }
        for (dim, ((&v, &lo), &hi)) in x.iter().zip(bounds.lo()).zip(bounds.hi()).enumerate() {
            if !(lo <= v && v <= hi) {
                return Err(FireflyError::InitialPositionOutOfBounds {
                    index,
                    dim,
                    value: v,
                    lo,
                    hi,
                });
            }
        }
    }
    Ok(())
}
