//! Tracing in rounds without waiting at their ends.
//!
//! ```text
//! blutrace trace SCENE [--photons N] [--target-error E] [--max-time S] [--threads T]
//! ```
//!
//! A run's photons go in rounds (growing 1.5x, in whole round units of [`GROUPS`] chunks);
//! after each, the metrics and their errors become a row of the convergence history and
//! the stopping rules are asked. The workers never wait for that: each takes the next
//! chunk in index order and sends what it traced to the calling thread, which absorbs the
//! chunks of the current round, holds those of the next, and takes the round's row as
//! soon as its last chunk arrives, while the workers trace on. Workers may run past the
//! current round's end as far as they trace in twice the time the last round's metrics
//! took, at least one round unit; when a rule stops the run, the chunks traced beyond its
//! last round (about that much work) are dropped, and the tallies hold exactly the
//! rounds' photons. Every chunk is the same whichever worker traced it and the sums are
//! integers, so results do not depend on the thread count; without the wait, a round's
//! end no longer leaves all but one worker idle (with many threads, most of them).

use super::metrics::{self, GROUPS, MetricValues, ScoredBins};
use super::{ConvergenceRow, Progress, RunOptions, StoppedBy, UNREACHABLE_AFTER, relative_error};
use crate::scene::Scene;
use crate::tally::{ChunkTally, Tally};
use crate::tracer::{CHUNK, Tracer};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// Photons per round unit: one chunk for every group.
const ROUND_UNIT: u64 = CHUNK * GROUPS as u64;

/// The state of a run between rounds.
pub(super) struct Rounds {
    first: u64,
    last: u64,
    /// Photons absorbed: the end of the last recorded round.
    pub(super) traced: u64,
    pub(super) total: Tally,
    pub(super) groups: Vec<Tally>,
    /// The flux bins each group has scored in (for the jackknife).
    scored: ScoredBins,
    pub(super) history: Vec<ConvergenceRow>,
    /// The metrics with each group left out, after the last round.
    pub(super) leave_out: Vec<MetricValues>,
}

/// What a run's workers share: the next chunk to take, how far they may go, and whether
/// to stop.
struct Gate {
    next: AtomicU64,
    /// Chunks below this index may be traced.
    limit: AtomicU64,
    stop: AtomicBool,
    wait: Mutex<()>,
    moved: Condvar,
    /// Workers waiting for the limit to move or done with their work: when all are, no
    /// chunk is on its way.
    idle: AtomicUsize,
}

impl Gate {
    /// The next chunk below `end` to trace, once the limit allows it; None when there
    /// is none or the run stopped.
    fn take(&self, end: u64) -> Option<u64> {
        let c = self.next.fetch_add(1, Ordering::Relaxed);
        if c >= end {
            return None;
        }
        if c < self.limit.load(Ordering::Acquire) && !self.stopped() {
            return Some(c);
        }
        let mut guard = lock(&self.wait);
        self.idle.fetch_add(1, Ordering::SeqCst);
        while c >= self.limit.load(Ordering::Acquire) && !self.stopped() {
            guard = self.moved.wait(guard).unwrap_or_else(|e| e.into_inner());
        }
        self.idle.fetch_sub(1, Ordering::SeqCst);
        (!self.stopped()).then_some(c)
    }

    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Acquire)
    }

    /// Let chunks below `limit` be traced.
    fn raise(&self, limit: u64) {
        self.limit.store(limit, Ordering::Release);
        self.wake();
    }

    /// Stop the workers after the chunks they are tracing.
    fn halt(&self) {
        self.stop.store(true, Ordering::Release);
        self.wake();
    }

    fn wake(&self) {
        // Under the lock, so no worker is between its check and its wait.
        let _guard = lock(&self.wait);
        self.moved.notify_all();
    }
}

/// Halts the gate when its thread unwinds: a worker's panic stops the others instead of
/// leaving the calling thread waiting for its chunk, and the calling thread's stops the
/// workers the scope would otherwise wait for (the run then fails with the panic).
struct HaltOnPanic<'a>(&'a Gate);

impl Drop for HaltOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.halt();
        }
    }
}

impl Rounds {
    /// Nothing traced yet of the photons `first..last` of `scene`.
    pub(super) fn new(scene: &Scene, (first, last): (u64, u64)) -> Self {
        Self {
            first,
            last,
            traced: first,
            total: Tally::new(scene),
            groups: vec![Tally::new(scene); GROUPS],
            scored: ScoredBins::new(GROUPS, scene.detector.bins[0] * scene.detector.bins[1]),
            history: Vec::new(),
            leave_out: Vec::new(),
        }
    }

    /// Trace rounds on `pool`'s workers until a stopping rule of `o` holds (time counted
    /// from `start`); `progress` is told the photons of each chunk absorbed.
    pub(super) fn run(
        &mut self,
        pool: &rayon::ThreadPool,
        tracer: &Tracer,
        scene: &Scene,
        o: &RunOptions,
        start: Instant,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> StoppedBy {
        if self.traced >= self.last {
            return StoppedBy::Photons;
        }
        let end = self.next_round_end(o, start.elapsed().as_secs_f64());
        let gate = Gate {
            next: AtomicU64::new(self.traced / CHUNK),
            limit: AtomicU64::new(end.div_ceil(CHUNK) + GROUPS as u64),
            stop: AtomicBool::new(false),
            wait: Mutex::new(()),
            moved: Condvar::new(),
            idle: AtomicUsize::new(0),
        };
        let (last, seed) = (self.last, o.seed);
        let (tx, rx) = channel();
        pool.in_place_scope(|s| {
            for _ in 0..pool.current_num_threads() {
                let (gate, tx) = (&gate, tx.clone());
                s.spawn(move |_| work(gate, tracer, seed, last, tx));
            }
            drop(tx);
            let _halt = HaltOnPanic(&gate);
            let why = self.absorb_rounds(pool, scene, o, start, end, &gate, &rx, progress);
            gate.halt();
            why
        })
    }

    /// The calling thread's part of [`Rounds::run`]: absorb chunks in index order as
    /// they arrive (holding any that come early), record each round as it completes, until
    /// a rule stops the run. In index order, the tallies always hold a whole prefix of the
    /// run's photons, so an interrupt or the time budget can end the run after any chunk.
    #[allow(clippy::too_many_arguments)]
    fn absorb_rounds(
        &mut self,
        pool: &rayon::ThreadPool,
        scene: &Scene,
        o: &RunOptions,
        start: Instant,
        mut end: u64,
        gate: &Gate,
        rx: &Receiver<ChunkTally>,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> StoppedBy {
        let mut early: BTreeMap<u64, ChunkTally> = BTreeMap::new();
        let mut next = self.traced / CHUNK;
        loop {
            while next < end.div_ceil(CHUNK) {
                let Some(chunk) = early.remove(&next) else {
                    let chunk = receive(rx, gate, pool.current_num_threads());
                    early.insert(chunk.index, chunk);
                    continue;
                };
                self.absorb(&chunk, progress);
                next += 1;
                if let Some(why) = self.cut_short(o, start) {
                    self.traced = (next * CHUNK).min(self.last);
                    self.record(scene, start.elapsed().as_secs_f64());
                    return why;
                }
            }
            self.traced = end;
            let seconds = start.elapsed().as_secs_f64();
            let recording = Instant::now();
            if end == self.last {
                // No chunk is left to trace: the workers are free to share the
                // jackknife (asking them earlier would wait for their chunks).
                pool.install(|| self.record(scene, seconds));
            } else {
                self.record(scene, seconds);
            }
            progress(Progress::Round {
                photons: self.traced - self.first,
                rel_error: self.target_rel_error(o),
            });
            if let Some(why) = self.stop_reason(o, seconds) {
                return why;
            }
            end = self.next_round_end(o, seconds);
            gate.raise(end.div_ceil(CHUNK) + self.lead(seconds, recording.elapsed().as_secs_f64()));
        }
    }

    /// A reason to end the run inside a round, after any chunk: an interrupt, or the time
    /// budget spent.
    fn cut_short(&self, o: &RunOptions, start: Instant) -> Option<StoppedBy> {
        if o.interrupt.requested() {
            return Some(StoppedBy::Interrupted);
        }
        match o.max_time_s {
            Some(t) if start.elapsed().as_secs_f64() >= t => Some(StoppedBy::Time),
            _ => None,
        }
    }

    /// How many chunks past a round's end the workers may go: as many as they trace in
    /// twice the time the last round's metrics took (`recorded` s, after `seconds` s of
    /// tracing), at least one round unit. So they do not wait for the metrics of a fine
    /// detector (a million bins take about a second), and a stopping rule drops at most
    /// about that much work.
    fn lead(&self, seconds: f64, recorded: f64) -> u64 {
        let chunks_per_s = (self.traced - self.first) as f64 / CHUNK as f64 / seconds;
        let cover = (2.0 * recorded * chunks_per_s).ceil();
        // (NaN, from a zero time, falls to the floor.)
        (cover.min(1e9) as u64).max(GROUPS as u64)
    }

    /// Score a traced chunk into its group and the total.
    fn absorb(&mut self, chunk: &ChunkTally, progress: &(dyn Fn(Progress) + Sync)) {
        let scored = chunk.scored();
        let xyz = self.total.scored_xyz(chunk);
        let g = (chunk.index % GROUPS as u64) as usize;
        self.groups[g].absorb_scored(chunk, &scored, &xyz);
        let bins = &mut self.scored.sets_mut()[g];
        chunk.detections.iter().for_each(|d| bins.mark(d.flux_bin));
        self.total.absorb_scored(chunk, &scored, &xyz);
        progress(Progress::Chunk(chunk.ledger.photons));
    }

    /// The target metric's relative error after the last round (NaN without a target).
    fn target_rel_error(&self, o: &RunOptions) -> f64 {
        match (o.target_error, self.history.last()) {
            (Some(_), Some(row)) => {
                let m = o.target_metric.metric();
                relative_error(m, row.values[m], row.stderr[m])
            }
            _ => f64::NAN,
        }
    }

    fn stop_reason(&self, o: &RunOptions, elapsed: f64) -> Option<StoppedBy> {
        if self.traced >= self.last {
            return Some(StoppedBy::Photons);
        }
        if let (Some(target), Some(row)) = (o.target_error, self.history.last()) {
            let m = o.target_metric.metric();
            let rel = relative_error(m, row.values[m], row.stderr[m]);
            if rel <= target {
                return Some(StoppedBy::TargetError);
            }
            // 0/0: no value (a ratio of nothing detected is NaN), or a zero with no error.
            let (value, err) = (row.values[m], row.stderr[m]);
            let no_error = err.is_nan() || err <= 0.0;
            let undefined = rel.is_nan() || !value.is_finite() || (value == 0.0 && no_error);
            if undefined && self.traced - self.first >= UNREACHABLE_AFTER {
                return Some(StoppedBy::Unreachable);
            }
        }
        match o.max_time_s {
            Some(t) if elapsed >= t => Some(StoppedBy::Time),
            _ => None,
        }
    }

    /// Rounds grow geometrically (x1.5), in whole round units, so history points are
    /// evenly spaced on log axes; a round is shrunk to fit the remaining time budget.
    fn next_round_end(&self, o: &RunOptions, elapsed: f64) -> u64 {
        let done = self.traced - self.first;
        let mut size = (done / 2).max(ROUND_UNIT).div_ceil(ROUND_UNIT) * ROUND_UNIT;
        if let (Some(limit), true) = (o.max_time_s, done > 0 && elapsed > 0.0) {
            let rate = done as f64 / elapsed;
            let fits = ((limit - elapsed) * rate) as u64 / ROUND_UNIT * ROUND_UNIT;
            size = size.min(fits.max(ROUND_UNIT));
        }
        (self.traced + size).min(self.last)
    }

    fn record(&mut self, scene: &Scene, seconds: f64) {
        let e = metrics::estimates(scene, &self.total, &self.groups, &self.scored);
        self.history.push(ConvergenceRow {
            photons: self.traced,
            seconds,
            values: e.values,
            stderr: e.stderr,
        });
        self.leave_out = e.leave_out;
    }
}

/// A worker: trace chunks `gate` hands out (photons below `last`) and send them on, until
/// there are none or the run stops.
fn work(gate: &Gate, tracer: &Tracer, seed: u64, last: u64, tx: Sender<ChunkTally>) {
    let _halt = HaltOnPanic(gate);
    while let Some(c) = gate.take(last.div_ceil(CHUNK)) {
        if tx.send(tracer.trace_chunk(seed, c, last)).is_err() {
            break;
        }
    }
    gate.idle.fetch_add(1, Ordering::SeqCst);
}

/// The next chunk from the `workers` behind `gate`, for a round still missing chunks.
/// Panics, rather than waiting for ever, when none can come: every worker gone (one
/// panicked, and the scope re-raises its panic once this one unwinds), or every worker
/// idle with nothing sent (a chunk lost in the rounds' bookkeeping: a bug).
fn receive(rx: &Receiver<ChunkTally>, gate: &Gate, workers: usize) -> ChunkTally {
    loop {
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(chunk) => return chunk,
            Err(RecvTimeoutError::Disconnected) => panic!("a worker ended without its chunk"),
            Err(RecvTimeoutError::Timeout) => {
                // A worker sends before it turns idle, so once all are idle, whatever
                // they sent is in the channel.
                if gate.idle.load(Ordering::SeqCst) == workers {
                    match rx.try_recv() {
                        Ok(chunk) => return chunk,
                        Err(_) => panic!("every worker is idle and a round misses a chunk"),
                    }
                }
            }
        }
    }
}

/// Lock `m`; a thread that panicked holding it has already failed the run.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gate(limit: u64) -> Gate {
        Gate {
            next: AtomicU64::new(0),
            limit: AtomicU64::new(limit),
            stop: AtomicBool::new(false),
            wait: Mutex::new(()),
            moved: Condvar::new(),
            idle: AtomicUsize::new(0),
        }
    }

    /// Workers wait at the limit, go on when it is raised, and stop when halted.
    #[test]
    fn the_gate_hands_out_chunks_in_order_up_to_its_limit() {
        let g = gate(2);
        assert_eq!((g.take(10), g.take(10)), (Some(0), Some(1)));
        std::thread::scope(|s| {
            let waiting = s.spawn(|| g.take(10));
            while g.idle.load(Ordering::SeqCst) == 0 {
                std::thread::yield_now();
            }
            g.raise(3);
            assert_eq!(waiting.join().unwrap(), Some(2));
            let parked = s.spawn(|| g.take(10));
            while g.idle.load(Ordering::SeqCst) == 0 {
                std::thread::yield_now();
            }
            g.halt();
            assert_eq!(parked.join().unwrap(), None);
        });
        assert_eq!(g.take(4), None, "past the end");
    }

    /// A round waiting for a chunk no worker will send fails instead of hanging.
    #[test]
    fn a_chunk_that_cannot_come_is_a_panic_not_a_hang() {
        let g = gate(0);
        let (tx, rx) = channel::<ChunkTally>();
        std::thread::scope(|s| {
            let workers: Vec<_> = (0..2).map(|_| s.spawn(|| g.take(10))).collect();
            let lost =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| receive(&rx, &g, 2)));
            let why = lost
                .err()
                .and_then(|e| e.downcast_ref::<&str>().map(|s| s.to_string()));
            assert_eq!(
                why.as_deref(),
                Some("every worker is idle and a round misses a chunk")
            );
            g.halt();
            workers
                .into_iter()
                .for_each(|w| assert_eq!(w.join().unwrap(), None));
        });
        drop(tx);
    }
}
