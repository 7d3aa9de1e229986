//! Neighbours along a race: per plane, the weights sorted by angle, each
//! with the next (and the last with the first). Two weights can only touch
//! if no third sits between them, so contact and the gap gauge need only
//! these pairs: O(n log n) per call instead of O(n²).

use std::f64::consts::TAU;

/// Most weights a ring sorts on the stack (the study limit on weights per
/// balancer); callers check every pair beyond it.
pub const MAX_RING: usize = 256;

/// Call `visit(a, b)` with a < b for every pair of neighbours among the
/// items 0..n (n ≤ [`MAX_RING`]) for which `in_ring` holds, ring by ring:
/// items of one `plane`, ordered by `angle` (any real, taken modulo 2π).
/// Planes come in the order of their first item, pairs in ring order, so
/// that a caller summing forces gets the same bits every time. No
/// allocation: the order lives on the stack.
pub fn for_each_neighbour_pair(
    n: usize,
    plane: impl Fn(usize) -> usize,
    in_ring: impl Fn(usize) -> bool,
    angle: impl Fn(usize) -> f64,
    mut visit: impl FnMut(usize, usize),
) {
    for_each_ring_pair(n, plane, in_ring, angle, |a, b, _| {
        visit(a.min(b), a.max(b))
    });
}

/// [`for_each_neighbour_pair`] with each pair in ring order: `visit(from,
/// to, ring length)`, `to` the next item along the ring after `from` (a
/// ring of two gives its one pair once).
pub fn for_each_ring_pair(
    n: usize,
    plane: impl Fn(usize) -> usize,
    in_ring: impl Fn(usize) -> bool,
    angle: impl Fn(usize) -> f64,
    mut visit: impl FnMut(usize, usize, usize),
) {
    for_each_ring(n, plane, in_ring, angle, |ring| {
        let m = ring.len();
        let pairs = if m > 2 { m } else { m.saturating_sub(1) };
        for i in 0..pairs {
            visit(ring[i] as usize, ring[(i + 1) % m] as usize, m);
        }
    });
}

/// Call `visit(ring)` for each plane's ring: the items 0..n (n ≤
/// [`MAX_RING`]) of that plane for which `in_ring` holds, sorted by `angle`
/// modulo 2π, planes in the order of their first item (a plane without such
/// items gives an empty ring). No allocation.
pub fn for_each_ring(
    n: usize,
    plane: impl Fn(usize) -> usize,
    in_ring: impl Fn(usize) -> bool,
    angle: impl Fn(usize) -> f64,
    mut visit: impl FnMut(&[u16]),
) {
    assert!(n <= MAX_RING, "{n} weights in a ring, at most {MAX_RING}");
    let mut order = [0u16; MAX_RING];
    let mut wrapped = [0.0f64; MAX_RING];
    for (i, w) in wrapped.iter_mut().enumerate().take(n) {
        *w = angle(i).rem_euclid(TAU);
    }
    for first in 0..n {
        let p = plane(first);
        // Each plane once: at its first item.
        if (0..first).any(|i| plane(i) == p) {
            continue;
        }
        let mut m = 0;
        for i in first..n {
            if plane(i) == p && in_ring(i) {
                order[m] = i as u16;
                m += 1;
            }
        }
        let ring = &mut order[..m];
        ring.sort_unstable_by(|&a, &b| wrapped[a as usize].total_cmp(&wrapped[b as usize]));
        visit(ring);
    }
}
