//! Settings of the FA-DAE solver: the project's defaults ([`FaDaeOptions::default`]) and the
//! paper's stated settings ([`FaDaeOptions::paper`]).

use crate::error::FaDaeError;
use mbd_firefly::{BoundaryHandling, DistanceScaling, FireflySettings, Termination, Variant};

/// How the coordinates are split into independent (optimised) and dependent (completed) ones.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub enum PartitionChoice {
    /// Gaussian elimination with complete pivoting of `Phi_q` at the system's initial state
    /// (default); re-chosen at a step's start when the dependent block has become much worse
    /// than the best available one (`|det Phi_d| / |det Phi_best|` below
    /// [`FaDaeOptions::repartition_threshold`]).
    #[default]
    Auto,
    /// These coordinate indices are independent (exactly [`mbd_model::System::dof`] `=
    /// n - m + k` distinct indices, `k` redundant equations, whose dependent block of `Phi_q`
    /// is invertible). Never re-chosen (with redundant equations only the `m - k` equations
    /// that complete them are): a singular dependent block during the run is an error.
    Given(Vec<usize>),
}

/// The predictor of the next state (the centre of the first search box).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Predictor {
    /// One classic RK4 step on the index-1 form from the accepted state.
    Rk4,
    /// The RK4 step plus the correction the optimiser applied to the RK4 step in the previous
    /// step (default): RK4 and the Gauss discretisation differ by a smooth `O(h^5)` amount,
    /// so last step's difference predicts this step's to `O(h^6)`.
    #[default]
    CorrectedRk4,
}

/// What a step does when the optimiser stops (stagnation or generation limit) above the
/// step's target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MissPolicy {
    /// Accept the best candidate found (it is a consistent state: all constraint levels hold
    /// whatever the candidate), flag the step in [`StepInfo::reached_target`](crate::StepInfo)
    /// and count it in [`FaDaeStats::target_misses`](crate::FaDaeStats) (default).
    #[default]
    Accept,
    /// Return [`FaDaeError::TargetMissed`] (a `SolveError::Newton` through the
    /// `Integrator` trait).
    Error,
}

/// The search box around the predictor, per step. See `docs/firefly-gauss.md`, section 2.7.
///
/// The position half-width is `w_z = safety * max(e_z, h e_v)`, where `(e_z, e_v)` is the
/// estimated error of the predictor in positions and velocities (max norm over the group): the
/// change of the optimiser's correction between the last two steps (corrected predictor), the
/// last correction (plain RK4 predictor, or the second step), or on the first step (and after a
/// repartition) the Richardson estimate `16/15 |RK4(h) - RK4(h/2)^2|`. The velocity half-width
/// is `w_z / h` (balanced). Both are floored at `min_relative * (1 + max_i |x_i|)` over the
/// group. Between stages the box is re-centred on the best point and shrunk by
/// `clamp(safety * sqrt(f_best / f_centre), min_shrink, max_shrink)`; if the best point lies
/// within `edge_fraction` of the box width from a face, the box is widened by `expansion`
/// instead (at most `max_expansions` times per step).
///
/// Defaults (a test compares this table with [`BoxSettings::default`]):
///
/// | field | default |
/// |---|---|
/// | `safety` | 2 |
/// | `min_relative` | 4e-15 (about 16 ulps) |
/// | `edge_fraction` | 0.02 |
/// | `expansion` | 10 |
/// | `max_expansions` | 6 |
/// | `min_shrink` | 0.01 |
/// | `max_shrink` | 0.5 |
#[derive(Clone, Debug, PartialEq)]
pub struct BoxSettings {
    /// Multiple of the predictor's estimated error used as half-width (at least 1).
    pub safety: f64,
    /// Relative floor of the half-width.
    pub min_relative: f64,
    /// Fraction of the width that counts as "at the face" (in `[0, 0.5)`).
    pub edge_fraction: f64,
    /// Widening factor when the best point is at a face (> 1).
    pub expansion: f64,
    /// Widenings allowed per step.
    pub max_expansions: u32,
    /// Smallest shrink factor between stages.
    pub min_shrink: f64,
    /// Largest shrink factor between stages (< 1).
    pub max_shrink: f64,
}

impl Default for BoxSettings {
    fn default() -> Self {
        BoxSettings {
            safety: 2.0,
            min_relative: 4e-15,
            edge_fraction: 0.02,
            expansion: 10.0,
            max_expansions: 6,
            min_shrink: 0.01,
            max_shrink: 0.5,
        }
    }
}

/// Settings of [`FireflyGauss`](crate::FireflyGauss).
///
/// [`FaDaeOptions::default`] is the **project's default**: the paper's firefly parameters and
/// generation limit where the scan is legible (population 60, `beta0 = 1`, `gamma = 1`,
/// `alpha = 0.7`, at most 1000 generations per step), the project's reading where it is not
/// (alpha decay 0.7), and the project's own choices for everything the paper does not state
/// (predictor, search box, stages) and for the stopping rule: `tolerance = 1e-2`, i.e. every
/// step improves the predictor's objective a hundredfold, where the paper states
/// `epsilon = 1e-7`. [`FaDaeOptions::paper`] is the same with the paper's `1e-7` (read as a
/// relative target); `docs/firefly-gauss.md` (section 2.8) explains the choice.
///
/// Defaults (a test compares this table with [`FaDaeOptions::default`]; the search box has its
/// own table on [`BoxSettings`]):
///
/// | field | default |
/// |---|---|
/// | `partition` | [`PartitionChoice::Auto`] |
/// | `firefly.population` | 60 (paper) |
/// | `firefly.beta0` | 1 (paper) |
/// | `firefly.beta_min` | 0 |
/// | `firefly.gamma` | 1 (paper) |
/// | `firefly.alpha` | 0.7 (paper) |
/// | `firefly.alpha_decay` | 0.7 (the scan's second 0.7, read as the decay) |
/// | `firefly.variant` | [`Variant::Snapshot`] |
/// | `firefly.boundary` | [`BoundaryHandling::Clamp`] |
/// | `firefly.distance` | [`DistanceScaling::Normalized`] |
/// | `firefly.best_random_walk` | true |
/// | `max_generations` | 1000 (paper) |
/// | `tolerance` | 1e-2 (relative: target = `tolerance * objective(predictor)`; paper: 1e-7, see [`FaDaeOptions::paper`]) |
/// | `stage_generations` | 12 |
/// | `stagnation_generations` | 2 |
/// | `predictor` | [`Predictor::CorrectedRk4`] |
/// | `bounds` | [`BoxSettings::default`] |
/// | `seed` | 0 |
/// | `seed_predictor` | true |
/// | `polish` | false |
/// | `polish_max_iter` | 8 |
/// | `parallel` | false |
/// | `newton_tol` | 1e-14 |
/// | `newton_max_iter` | 10 |
/// | `on_miss` | [`MissPolicy::Accept`] |
/// | `repartition_threshold` | 0.1 |
/// | `predictor_offset` | 0 |
#[derive(Clone, Debug, PartialEq)]
pub struct FaDaeOptions {
    /// Coordinate partitioning.
    pub partition: PartitionChoice,
    /// The firefly algorithm's parameters. Its `seed` field is ignored: every step uses its own
    /// seed derived from [`FaDaeOptions::seed`] and the step index.
    pub firefly: FireflySettings,
    /// Generation limit of a step, over all its stages (the paper's limit per step).
    pub max_generations: u64,
    /// Relative target: the optimiser stops once the objective is at most
    /// `tolerance * objective(predictor)` (or at the round-off floor of the objective). The
    /// paper states `epsilon = 1e-7` ([`FaDaeOptions::paper`]); the default is `1e-2`.
    pub tolerance: f64,
    /// Generation limit of one stage (one firefly run in one box).
    pub stage_generations: u64,
    /// A stage stops after this many generations without any improvement of the best value
    /// (`None`: off).
    pub stagnation_generations: Option<u64>,
    /// The predictor.
    pub predictor: Predictor,
    /// The search box.
    pub bounds: BoxSettings,
    /// Seed of the run; step `k` uses a seed mixed from it and `k`.
    pub seed: u64,
    /// Put the predictor into the initial population as firefly 0.
    pub seed_predictor: bool,
    /// Polish the firefly's result by Gauss-Newton on the same residual (off: the paper's pure
    /// firefly).
    pub polish: bool,
    /// Gauss-Newton iteration limit of the polish.
    pub polish_max_iter: usize,
    /// Evaluate each generation in parallel with rayon (bit-identical to serial).
    pub parallel: bool,
    /// Newton tolerance on `||Phi||_inf` for the dependent coordinates, relative to the largest
    /// translational coordinate (at least 1); must be at most 1e-12.
    pub newton_tol: f64,
    /// Chord Newton iteration limit.
    pub newton_max_iter: usize,
    /// Behaviour when the optimiser misses the target.
    pub on_miss: MissPolicy,
    /// Auto partitioning: at each step's start, the quality of the dependent block in use is
    /// `|det Phi_d| / |det Phi_best|`, where `Phi_best` is the block that Gaussian elimination
    /// with complete pivoting of `Phi_q` picks (the product of its pivots); the partition is
    /// re-chosen (to the complete-pivoting choice) when the quality falls below this threshold.
    /// Relative to the best choice, so it also works for a single constraint (a 1x1 block is
    /// always perfectly conditioned on its own, but not relative to the row: a distance joint
    /// at the bottom of the swing). Must be in `[0, 0.5]`: a fresh choice has quality 1, so
    /// it is replaced only after its conditioning worsened at least twofold relative to the
    /// best (no thrashing). 0 switches repartitioning off.
    pub repartition_threshold: f64,
    /// Diagnostic: shift the predictor (and the box centred on it) by this fraction of the box
    /// half-width, with alternating signs per coordinate. Used to show that the answer comes
    /// from the optimiser, not from the predictor.
    pub predictor_offset: f64,
}

impl Default for FaDaeOptions {
    fn default() -> Self {
        FaDaeOptions {
            partition: PartitionChoice::Auto,
            firefly: FireflySettings::default()
                .population(60)
                .beta0(1.0)
                .beta_min(0.0)
                .gamma(1.0)
                .alpha(0.7)
                .alpha_decay(0.7)
                .variant(Variant::Snapshot)
                .boundary(BoundaryHandling::Clamp)
                .distance(DistanceScaling::Normalized)
                .best_random_walk(true),
            max_generations: 1000,
            tolerance: 1e-2,
            stage_generations: 12,
            stagnation_generations: Some(2),
            predictor: Predictor::CorrectedRk4,
            bounds: BoxSettings::default(),
            seed: 0,
            seed_predictor: true,
            polish: false,
            polish_max_iter: 8,
            parallel: false,
            newton_tol: 1e-14,
            newton_max_iter: 10,
            on_miss: MissPolicy::Accept,
            repartition_threshold: 0.1,
            predictor_offset: 0.0,
        }
    }
}

impl FaDaeOptions {
    /// The paper's stated settings: the default (pure firefly, population 60, `beta0 = 1`,
    /// `gamma = 1`, `alpha = 0.7`, at most 1000 generations per step) with the paper's
    /// `epsilon = 1e-7` as [`FaDaeOptions::tolerance`] (read as a relative target: as an absolute
    /// bound on this objective it would be met by the predictor alone). The predictor, the
    /// search box and its stages are the project's (the paper states none). It reaches the
    /// polished variant's accuracy with about five times the generations of the default.
    pub fn paper() -> Self {
        FaDaeOptions {
            tolerance: 1e-7,
            ..Self::default()
        }
    }

    /// The default with the Gauss-Newton polish switched on.
    pub fn polished() -> Self {
        FaDaeOptions {
            polish: true,
            ..Self::default()
        }
    }

    /// Sets [`FaDaeOptions::seed`].
    #[must_use]
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets [`FaDaeOptions::parallel`].
    #[must_use]
    pub fn parallel(mut self, on: bool) -> Self {
        self.parallel = on;
        self
    }

    /// Sets [`FaDaeOptions::polish`].
    #[must_use]
    pub fn polish(mut self, on: bool) -> Self {
        self.polish = on;
        self
    }

    /// Sets [`FaDaeOptions::partition`].
    #[must_use]
    pub fn partition(mut self, p: PartitionChoice) -> Self {
        self.partition = p;
        self
    }

    /// The optimiser's stopping rules for one stage of a step.
    pub(crate) fn stage_termination(&self, target: f64, remaining: u64) -> Termination {
        let mut t = Termination::default()
            .max_generations(self.stage_generations.min(remaining).max(1))
            .target(target);
        if let Some(k) = self.stagnation_generations {
            t = t.stagnation(k, 0.0);
        }
        t
    }

    /// Checks every option.
    ///
    /// # Errors
    /// [`FaDaeError::InvalidOption`] naming the first bad field, or [`FaDaeError::Firefly`]
    /// for invalid firefly settings or stopping rules.
    pub fn validate(&self) -> Result<(), FaDaeError> {
        self.firefly.validate()?;
        self.stage_termination(0.0, 1).validate()?;
        let bad = |name: &'static str, value: f64, requirement: &'static str| {
            Err(FaDaeError::InvalidOption {
                name,
                value,
                requirement,
            })
        };
        if self.max_generations == 0 {
            return bad("max_generations", 0.0, ">= 1");
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            return bad("tolerance", self.tolerance, "finite and in (0, 1)");
        }
        let b = &self.bounds;
        if !(b.safety.is_finite() && b.safety >= 1.0) {
            return bad("bounds.safety", b.safety, "finite and >= 1");
        }
        if !(b.min_relative.is_finite() && b.min_relative > 0.0) {
            return bad("bounds.min_relative", b.min_relative, "finite and > 0");
        }
        if !(b.edge_fraction.is_finite() && b.edge_fraction >= 0.0 && b.edge_fraction < 0.5) {
            return bad("bounds.edge_fraction", b.edge_fraction, "in [0, 0.5)");
        }
        if self.stage_generations == 0 {
            return bad("stage_generations", 0.0, ">= 1");
        }
        if !(b.min_shrink > 0.0 && b.min_shrink <= b.max_shrink && b.max_shrink < 1.0) {
            return bad(
                "bounds.min_shrink",
                b.min_shrink,
                "0 < min_shrink <= max_shrink < 1",
            );
        }
        if !(b.expansion.is_finite() && b.expansion > 1.0) {
            return bad("bounds.expansion", b.expansion, "finite and > 1");
        }
        if !(self.newton_tol.is_finite() && self.newton_tol > 0.0 && self.newton_tol <= 1e-12) {
            return bad("newton_tol", self.newton_tol, "in (0, 1e-12]");
        }
        if self.newton_max_iter == 0 {
            return bad("newton_max_iter", 0.0, ">= 1");
        }
        if !(self.repartition_threshold >= 0.0 && self.repartition_threshold <= 0.5) {
            return bad(
                "repartition_threshold",
                self.repartition_threshold,
                "in [0, 0.5]",
            );
        }
        if !(self.predictor_offset.is_finite() && self.predictor_offset.abs() <= 1.0) {
            return bad(
                "predictor_offset",
                self.predictor_offset,
                "finite with |offset| <= 1",
            );
        }
        Ok(())
    }
}
