//! Algorithm parameters with documented defaults and builder-style setters.

use crate::FireflyError;

/// Which form of the firefly loop to run.
///
/// All variants use the same move rule (see the crate documentation); they
/// differ in which positions a move sees and in when the objective is called.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Variant {
    /// Yang's classic double loop, in place, evaluated after **every move**
    /// (as in Yang's 2008 pseudocode): for `i` in index order, for `j` in index
    /// order, if `j` is currently brighter than `i`, move `i` toward the
    /// *current* position of `j` and immediately re-evaluate `i`. Positions and
    /// brightness updated earlier in the generation are used at once. One
    /// generation costs up to `n (n - 1)` evaluations (data dependent).
    /// Always serial.
    Classic,
    /// The classic in-place double loop, but firefly `i` is evaluated once,
    /// **after its whole sweep** over `j` (during the sweep its old brightness
    /// is used). Moves see positions already updated this generation. One
    /// generation costs at most `n` evaluations. Always serial.
    ClassicSweep,
    /// The sorted snapshot variant (default). The population is sorted by
    /// brightness, copied into a snapshot, every firefly is moved toward every
    /// strictly brighter firefly *of the snapshot* (each firefly drawing from
    /// its own random stream), and then all new positions are evaluated. Moves
    /// and evaluations may run in parallel
    /// ([`Firefly::minimize_parallel`](crate::Firefly::minimize_parallel)); the
    /// result is bit-identical to the serial run. One generation costs at
    /// most `n` evaluations.
    #[default]
    Snapshot,
}

/// What happens to a coordinate that leaves the box after a move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BoundaryHandling {
    /// Project onto the nearest bound (default).
    #[default]
    Clamp,
    /// Mirror at the violated bound, folding repeatedly if the overshoot is
    /// larger than the box width (zero-width dimensions stay at the bound).
    Reflect,
}

/// How the distance `r` between two fireflies is measured for the
/// attractiveness `beta(r)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum DistanceScaling {
    /// Each coordinate difference is divided by the box width of its dimension
    /// before the Euclidean norm is taken (default); zero-width dimensions
    /// contribute nothing. This makes `gamma` independent of the problem's
    /// units: with `gamma = 1`, fireflies half a box apart in one dimension
    /// attract each other with `beta0 * exp(-1/4)`.
    #[default]
    Normalized,
    /// Plain Euclidean distance in the problem's own coordinates, as in Yang's
    /// reference code. A suitable `gamma` then depends on the box size
    /// (Yang suggests `gamma ~ 1 / L^2` for a length scale `L`).
    Raw,
}

/// Parameters of the firefly algorithm.
///
/// Fields are public; the same-named methods are builder-style setters:
///
/// ```
/// use mbd_firefly::{FireflySettings, Variant};
/// let s = FireflySettings::default()
///     .population(40)
///     .alpha(0.5)
///     .alpha_decay(0.95)
///     .variant(Variant::ClassicSweep)
///     .seed(7);
/// assert_eq!(s.population, 40);
/// ```
///
/// | field | default | valid range |
/// |---|---|---|
/// | `population` | 60 | `>= 1` |
/// | `beta0` | 1.0 | finite, `>= 0` |
/// | `beta_min` | 0.0 | finite, `0 <= beta_min <= beta0` |
/// | `gamma` | 1.0 | finite, `>= 0` |
/// | `alpha` | 0.7 | finite, `>= 0` |
/// | `alpha_decay` | 0.97 | `(0, 1]` |
/// | `variant` | [`Variant::Snapshot`] | |
/// | `boundary` | [`BoundaryHandling::Clamp`] | |
/// | `distance` | [`DistanceScaling::Normalized`] | |
/// | `best_random_walk` | `true` | |
/// | `seed` | 0 | any `u64` |
///
/// The defaults follow the parameters of the downstream DAE paper
/// (population 60, `beta0 = 1`, `gamma = 1`, `alpha = 0.7`, decay 0.97);
/// the generation limit (1000) lives in [`Termination`](crate::Termination).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FireflySettings {
    /// Number of fireflies `n`.
    pub population: usize,
    /// Attractiveness at distance zero, `beta0`.
    pub beta0: f64,
    /// Minimum attractiveness, `beta(r) = (beta0 - beta_min) exp(-gamma r^2) + beta_min`.
    pub beta_min: f64,
    /// Light absorption coefficient `gamma`.
    pub gamma: f64,
    /// Initial randomisation strength `alpha_0`, relative to the box width:
    /// every move adds `alpha (u - 1/2) (hi_k - lo_k)` to coordinate `k`,
    /// `u ~ U[0, 1)`.
    pub alpha: f64,
    /// Geometric decay `delta` of `alpha` per generation: generation `t`
    /// (1-based) uses `alpha_0 delta^(t-1)`.
    pub alpha_decay: f64,
    /// Loop form, see [`Variant`].
    pub variant: Variant,
    /// Treatment of coordinates that leave the box.
    pub boundary: BoundaryHandling,
    /// Distance used in `beta(r)`.
    pub distance: DistanceScaling,
    /// Whether a firefly that has no brighter firefly to move toward (the
    /// current best, and any firefly tied with it) takes a pure random step
    /// `alpha (u - 1/2) (hi - lo)` instead (Yang's standard algorithm: `true`).
    /// With `false` such fireflies stay put and are not re-evaluated.
    pub best_random_walk: bool,
    /// Seed of the ChaCha8 random stream; same seed, same results.
    pub seed: u64,
}

impl Default for FireflySettings {
    fn default() -> Self {
        Self {
            population: 60,
            beta0: 1.0,
            beta_min: 0.0,
            gamma: 1.0,
            alpha: 0.7,
            alpha_decay: 0.97,
            variant: Variant::Snapshot,
            boundary: BoundaryHandling::Clamp,
            distance: DistanceScaling::Normalized,
            best_random_walk: true,
            seed: 0,
        }
    }
}

impl FireflySettings {
    /// Same as [`FireflySettings::default`].
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`population`](Self::population).
    #[must_use]
    pub fn population(mut self, n: usize) -> Self {
        self.population = n;
        self
    }

    /// Sets [`beta0`](Self::beta0).
    #[must_use]
    pub fn beta0(mut self, beta0: f64) -> Self {
        self.beta0 = beta0;
        self
    }

    /// Sets [`beta_min`](Self::beta_min).
    #[must_use]
    pub fn beta_min(mut self, beta_min: f64) -> Self {
        self.beta_min = beta_min;
        self
    }

    /// Sets [`gamma`](Self::gamma).
    #[must_use]
    pub fn gamma(mut self, gamma: f64) -> Self {
        self.gamma = gamma;
        self
    }

    /// Sets the initial [`alpha`](Self::alpha).
    #[must_use]
    pub fn alpha(mut self, alpha: f64) -> Self {
        self.alpha = alpha;
        self
    }

    /// Sets [`alpha_decay`](Self::alpha_decay).
    #[must_use]
    pub fn alpha_decay(mut self, delta: f64) -> Self {
        self.alpha_decay = delta;
        self
    }

    /// Sets [`variant`](Self::variant).
    #[must_use]
    pub fn variant(mut self, variant: Variant) -> Self {
        self.variant = variant;
        self
    }

    /// Sets [`boundary`](Self::boundary).
    #[must_use]
    pub fn boundary(mut self, boundary: BoundaryHandling) -> Self {
        self.boundary = boundary;
        self
    }

    /// Sets [`distance`](Self::distance).
    #[must_use]
    pub fn distance(mut self, distance: DistanceScaling) -> Self {
        self.distance = distance;
        self
    }

    /// Sets [`best_random_walk`](Self::best_random_walk).
    #[must_use]
    pub fn best_random_walk(mut self, on: bool) -> Self {
        self.best_random_walk = on;
        self
    }

    /// Sets [`seed`](Self::seed).
    #[must_use]
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Checks every parameter against the table above.
    ///
    /// # Errors
    /// [`FireflyError::ZeroPopulation`] or [`FireflyError::InvalidParameter`]
    /// naming the first offending field.
    pub fn validate(&self) -> Result<(), FireflyError> {
        if self.population == 0 {
            return Err(FireflyError::ZeroPopulation);
        }
        let nonneg = |name: &'static str, value: f64| {
            if value.is_finite() && value >= 0.0 {
                Ok(())
            } else {
                Err(FireflyError::InvalidParameter {
                    name,
                    value,
                    requirement: "finite and >= 0",
                })
            }
        };
        nonneg("beta0", self.beta0)?;
        nonneg("gamma", self.gamma)?;
        nonneg("alpha", self.alpha)?;
        if !(self.beta_min.is_finite() && self.beta_min >= 0.0 && self.beta_min <= self.beta0) {
            return Err(FireflyError::InvalidParameter {
                name: "beta_min",
                value: self.beta_min,
                requirement: "finite with 0 <= beta_min <= beta0",
            });
        }
        if !(self.alpha_decay > 0.0 && self.alpha_decay <= 1.0) {
            return Err(FireflyError::InvalidParameter {
                name: "alpha_decay",
                value: self.alpha_decay,
                requirement: "in (0, 1]",
            });
        }
        Ok(())
    }
}
