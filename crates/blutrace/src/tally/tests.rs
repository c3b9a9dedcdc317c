//! Unit tests of the tallies: exact sums, merges, sparse grids, checked merges.

use super::*;

#[test]
fn taking_a_part_out_leaves_exactly_the_rest() {
    let (mut a, mut b) = (Grid::new(3, 2), Grid::new(3, 2));
    for k in 0..200 {
        let w = 1.0 / (k as f64 + 0.37);
        a.add(k % 3, k % 2, w);
        b.add((k / 3) % 3, (k / 5) % 2, w * 1e-9);
    }
    let mut total = a.clone();
    total.merge(&b);
    assert_ne!(total, a);
    total.merge_signed(&b, Sign::Remove);
    assert_eq!(total, a);
}

#[test]
fn exact_sum_is_order_independent() {
    let xs: Vec<f64> = (0..10_000).map(|i| 1.0 / (1.0 + i as f64)).collect();
    let mut fwd = ExactSum::default();
    xs.iter().for_each(|&x| fwd.add(x));
    let mut rev = ExactSum::default();
    xs.iter().rev().for_each(|&x| rev.add(x));
    assert_eq!(fwd, rev);
}

#[test]
fn grid_round_trips_through_json_sparsely() {
    let mut g = Grid::new(3, 2);
    g.add(2, 1, 0.75);
    g.add(2, 1, 1e-12);
    let json = serde_json::to_string(&g).unwrap();
    assert_eq!(json.matches('[').count(), 2, "only one bin stored: {json}");
    let back: Grid = serde_json::from_str(&json).unwrap();
    assert_eq!(back, g);
    let bad = json.replace("[[5,", "[[9,");
    assert!(serde_json::from_str::<Grid>(&bad).is_err());
}

#[test]
fn stderr_of_bernoulli_matches_closed_form() {
    // 1000 samples, 250 ones: p = 0.25, stderr = sqrt(p(1-p)/(n-1)).
    let (m, s) = mean_and_stderr(250.0, 250.0, 1000);
    assert_eq!(m, 0.25);
    assert!((s - (0.25f64 * 0.75 / 999.0).sqrt()).abs() < 1e-15);
}

/// Tallies read from files add up with checked arithmetic: past the `i128` range is
/// `None`, never a wrapped sum or a panic.
#[test]
fn checked_merges_stop_at_the_counters_range() {
    let mut a = Grid::new(2, 1);
    let mut b = Grid::new(2, 1);
    a.bins[1].sum = ExactSum(i128::MAX);
    b.bins[1].sum = ExactSum(1);
    assert_eq!(a.checked_merge(&b), None);
    b.bins[1].sum = ExactSum(0);
    b.bins[0].hits = 3;
    assert_eq!(a.checked_merge(&b), Some(()));
    assert_eq!(a.bins[0].hits, 3);
    let mut l = Ledger {
        escaped: ExactSum(i128::MAX),
        ..Ledger::default()
    };
    assert_eq!(l.checked_accounted(), Some(ExactSum(i128::MAX)));
    l.killed = ExactSum(1);
    assert_eq!(l.checked_accounted(), None);
    let mut m = Ledger::default();
    assert_eq!(m.checked_merge(&l), Some(()));
    assert_eq!(m.checked_merge(&l), None);
}

#[test]
fn stokes_bins_no_run_could_score_are_refused() {
    let mut g = Grid::new(2, 1);
    // Two photons of weight 0.5, polarized +1 and -0.5: a sum of 0.25, squares 0.3125.
    g.add(0, 0, 0.5);
    g.add(0, 0, -0.25);
    assert!(!bad_stokes(&g, 2));
    assert!(bad_stokes(&g, 1), "more photons than emitted");
    let mut edited = g.clone();
    edited.bins[0].sum.add(1.0); // |sum| beyond what its squares allow
    assert!(bad_stokes(&edited, 2));
    // Terms below the grid's resolution squared: their squares add nothing, yet a run
    // scores them (nearly unpolarized light), so they are no damage.
    let mut faint = Grid::new(1, 1);
    (0..3).for_each(|_| faint.add(0, 0, 1e-12));
    assert_eq!(faint.bins[0].sumsq.0, 0);
    assert!(!bad_stokes(&faint, 3));
    let mut negative = g.clone();
    negative.bins[1].sumsq.0 = -1;
    assert!(bad_stokes(&negative, 2));
}
