//! Objective evaluation strategies of a generation: serial, or rayon-parallel batches with
//! results independent of scheduling.

use rayon::prelude::*;

use crate::{Objective, SyncObjective};

/// Objective evaluation strategy: serial or rayon-parallel batches.
pub(crate) trait Evaluator {
    /// Evaluates one point.
    fn one(&mut self, x: &[f64]) -> f64;

    /// For every row `i` (length `d`) of `rows`: runs `prepare(i, row)` (which
    /// may modify the row, e.g. move the firefly), then evaluates the row into
    /// `out[i]`. Rows are independent, so they may be processed in parallel.
    fn batch<P>(&mut self, rows: &mut [f64], d: usize, out: &mut [f64], prepare: P)
    where
        P: Fn(usize, &mut [f64]) + Sync;
}

pub(crate) struct SerialEval<'o, O: ?Sized>(pub(crate) &'o mut O);

impl<O: Objective + ?Sized> Evaluator for SerialEval<'_, O> {
    fn one(&mut self, x: &[f64]) -> f64 {
        self.0.eval(x)
    }

    fn batch<P>(&mut self, rows: &mut [f64], d: usize, out: &mut [f64], prepare: P)
    where
        P: Fn(usize, &mut [f64]) + Sync,
    {
        for (i, (row, o)) in rows.chunks_exact_mut(d).zip(out.iter_mut()).enumerate() {
            prepare(i, row);
            *o = self.0.eval(row);
        }
    }
}

pub(crate) struct ParallelEval<'o, O: ?Sized>(pub(crate) &'o O);

impl<O: SyncObjective + ?Sized> Evaluator for ParallelEval<'_, O> {
    fn one(&mut self, x: &[f64]) -> f64 {
        self.0.eval(x)
    }

    fn batch<P>(&mut self, rows: &mut [f64], d: usize, out: &mut [f64], prepare: P)
    where
        P: Fn(usize, &mut [f64]) + Sync,
    {
        let obj = self.0;
        // Each row is prepared from its own inputs and its value lands in its
        // own slot, so the outcome cannot depend on scheduling or on the
        // number of threads.
        rows.par_chunks_exact_mut(d)
            .zip(out.par_iter_mut())
            .enumerate()
            .for_each(|(i, (row, o))| {
                prepare(i, row);
                *o = obj.eval(row);
            });
    }
}
