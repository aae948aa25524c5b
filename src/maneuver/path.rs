//! Reference paths: polylines with arc length, densely sampled, open or closed.

/// A reference path: points (x, y) in the ground frame with cumulative arc length.
#[derive(Debug, Clone, PartialEq)]
pub struct RefPath {
    pts: Vec<(f64, f64)>,
    s: Vec<f64>,
    closed: bool,
}

impl RefPath {
    /// Path through `pts` (at least two distinct points). A closed path wraps around.
    pub fn new(pts: Vec<(f64, f64)>, closed: bool) -> Self {
        let mut s = Vec::with_capacity(pts.len());
        let mut acc = 0.0;
        for (i, p) in pts.iter().enumerate() {
            if i > 0 {
                let q = pts[i - 1];
                acc += (p.0 - q.0).hypot(p.1 - q.1);
            }
            s.push(acc);
        }
        Self { pts, s, closed }
    }

    /// Sample y = f(x) from x0 to x1 every `dx`.
    pub fn from_fn(x0: f64, x1: f64, dx: f64, f: impl Fn(f64) -> f64) -> Self {
        let n = ((x1 - x0) / dx).ceil().max(1.0) as usize;
        let pts = (0..=n).map(|i| {
            let x = x0 + (x1 - x0) * i as f64 / n as f64;
            (x, f(x))
        });
        Self::new(pts.collect(), false)
    }

    /// Total length, m (closing segment included for a closed path).
    pub fn length(&self) -> f64 {
        let open = *self.s.last().unwrap_or(&0.0);
        if self.closed && self.pts.len() > 1 {
            let (a, b) = (self.pts[0], self.pts[self.pts.len() - 1]);
            open + (a.0 - b.0).hypot(a.1 - b.1)
        } else {
            open
        }
    }

    pub fn start_s(&self) -> f64 {
        0.0
    }

    fn segment(&self, i: usize) -> ((f64, f64), (f64, f64), f64) {
        let n = self.pts.len();
        let j = if i + 1 < n { i + 1 } else { 0 };
        let s0 = self.s[i];
        (self.pts[i], self.pts[j], s0)
    }

    fn n_segments(&self) -> usize {
        if self.closed {
            self.pts.len()
        } else {
            self.pts.len().saturating_sub(1)
        }
    }

    fn wrap(&self, s: f64) -> f64 {
        if self.closed {
            let l = self.length();
            if l > 0.0 {
                return s.rem_euclid(l);
            }
        }
        s
    }

    /// Index of the segment holding arc length `s`.
    pub fn segment_at(&self, s: f64) -> usize {
        self.index_at(s)
    }

    fn index_at(&self, s: f64) -> usize {
        let s = self.wrap(s);
        match self.s.binary_search_by(|v| v.partial_cmp(&s).unwrap_or(std::cmp::Ordering::Less)) {
            Ok(i) => i.min(self.n_segments().saturating_sub(1)),
            Err(i) => i.saturating_sub(1).min(self.n_segments().saturating_sub(1)),
        }
    }

    /// Point at arc length `s` (extrapolated along the end segments of an open path).
    pub fn point_at(&self, s: f64) -> (f64, f64) {
        if self.pts.len() < 2 {
            return self.pts.first().copied().unwrap_or((0.0, 0.0));
        }
        let s = self.wrap(s);
        let i = self.index_at(s);
        let (a, b, s0) = self.segment(i);
        let len = (b.0 - a.0).hypot(b.1 - a.1).max(1e-12);
        let u = (s - s0) / len;
        (a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1))
    }

    /// Closest point to (x, y) over the whole path. Returns (arc length, signed lateral offset of
    /// the point, positive to the left of the path direction).
    ///
    /// An inner segment (a, b) whose every point is farther than a segment already projected by a
    /// coordinate alone (|x - a_x| - |b_x - a_x| or the same in y, less a 1 um margin for
    /// rounding, squared, beyond that squared distance) cannot be closer and is not projected: the
    /// same answer as projecting every segment, at a few comparisons per far segment. The end
    /// segments of an open path extend beyond their ends and are always projected.
    pub fn closest_global(&self, x: f64, y: f64) -> (f64, f64) {
        let nseg = self.n_segments();
        let mut best = (f64::INFINITY, 0.0, 0.0);
        // The segment starting nearest (x, y), projected first: its distance is a tight threshold
        // from the start (the search keeps the first closest segment in order, as before).
        let near = (0..nseg)
            .map(|i| (self.pts[i].0 - x).powi(2) + (self.pts[i].1 - y).powi(2))
            .enumerate()
            .fold((0, f64::INFINITY), |b, (i, d2)| if d2 < b.1 { (i, d2) } else { b });
        let seed = if nseg > 0 { self.project(near.0, x, y).0 } else { f64::INFINITY };
        for i in 0..nseg {
            if self.closed || (i > 0 && i + 1 < nseg) {
                let (a, b, _) = self.segment(i);
                let gap = ((x - a.0).abs() - (b.0 - a.0).abs()).max((y - a.1).abs() - (b.1 - a.1).abs()) - 1e-6;
                if gap > 0.0 && gap * gap > best.0.min(seed) {
                    continue;
                }
            }
            let p = self.project(i, x, y);
            if p.0 < best.0 {
                best = p;
            }
        }
        (self.wrap(best.1), best.2)
    }

    /// Closest point to (x, y) found by walking from the segment at arc length `hint_s` to
    /// neighbouring segments while they come closer (a few segments per call when the point moves
    /// little between calls; use [`RefPath::closest_global`] for the first call). Returns (arc
    /// length, signed lateral offset, positive to the left of the path direction).
    pub fn closest(&self, x: f64, y: f64, hint_s: f64) -> (f64, f64) {
        let (s, e, _) = self.closest_from(x, y, self.index_at(hint_s));
        (s, e)
    }

    /// As [`RefPath::closest`], starting from segment index `start`; also returns the segment
    /// index found, to start the next call from (no search over the path).
    pub fn closest_from(&self, x: f64, y: f64, start: usize) -> (f64, f64, usize) {
        let nseg = self.n_segments();
        if nseg == 0 {
            return (0.0, 0.0, 0);
        }
        let start = start.min(nseg - 1);
        let step = |i: usize, fwd: bool| -> Option<usize> {
            if fwd {
                if i + 1 < nseg {
                    Some(i + 1)
                } else if self.closed {
                    Some(0)
                } else {
                    None
                }
            } else if i > 0 {
                Some(i - 1)
            } else if self.closed {
                Some(nseg - 1)
            } else {
                None
            }
        };
        let mut best = (start, self.project(start, x, y));
        for fwd in [true, false] {
            if !fwd && best.0 != start {
                // The forward walk moved: the segment behind the best is the one it left, farther.
                break;
            }
            let mut i = best.0;
            // At most one lap: a closed path cannot make the walk cycle.
            for _ in 0..nseg {
                match step(i, fwd) {
                    Some(j) => {
                        let p = self.project(j, x, y);
                        if p.0 < best.1 .0 {
                            best = (j, p);
                            i = j;
                        } else {
                            break;
                        }
                    }
                    None => break,
                }
            }
        }
        let (_, s, e) = best.1;
        (self.wrap(s), e, best.0)
    }

    /// Point at arc length `s`, searching forward from segment index `from` (cheap when `s` lies
    /// a few segments ahead of it, as the driver's preview point does). `ahead` is a segment known
    /// from an earlier call (the previous preview's, returned as the second value): the walk
    /// starts there instead when it lies beyond `from` and starts at or before `s`, which gives
    /// the same segment (arc length never decreases along the path) in fewer steps.
    pub fn point_at_from(&self, s: f64, from: usize, ahead: usize) -> ((f64, f64), usize) {
        let nseg = self.n_segments();
        if nseg == 0 || self.closed {
            return (self.point_at(s), from);
        }
        let mut i = from.min(nseg - 1);
        if ahead > i && ahead < nseg && self.s[ahead] <= s {
            i = ahead;
        }
        while i + 1 < nseg && self.s[i + 1] <= s {
            i += 1;
        }
        if self.s[i] > s {
            return (self.point_at(s), from);
        }
        let (a, b, s0) = self.segment(i);
        let len = (b.0 - a.0).hypot(b.1 - a.1).max(1e-12);
        let u = (s - s0) / len;
        ((a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1)), i)
    }

    /// Projection of (x, y) on segment i: (squared distance, arc length, signed offset). The end
    /// segments of an open path extend beyond their ends.
    fn project(&self, i: usize, x: f64, y: f64) -> (f64, f64, f64) {
        let nseg = self.n_segments();
        let (a, b, s0) = self.segment(i);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = (dx * dx + dy * dy).max(1e-24);
        let mut u = ((x - a.0) * dx + (y - a.1) * dy) / len2;
        let last_open = !self.closed && i + 1 == nseg;
        let first_open = !self.closed && i == 0;
        let extends_beyond_end = (last_open && u > 1.0) || (first_open && u < 0.0);
        if !extends_beyond_end {
            u = u.clamp(0.0, 1.0);
        }
        let (px, py) = (a.0 + u * dx, a.1 + u * dy);
        let len = len2.sqrt();
        ((x - px).powi(2) + (y - py).powi(2), s0 + u * len, (dx * (y - a.1) - dy * (x - a.0)) / len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_line_offsets_and_arc_length() {
        let p = RefPath::from_fn(0.0, 100.0, 0.5, |_| 0.0);
        let (s, e) = p.closest(30.0, 1.5, 29.0);
        assert!((s - 30.0).abs() < 1e-9 && (e - 1.5).abs() < 1e-12);
        let (s, e) = p.closest_global(30.0, 1.5);
        assert!((s - 30.0).abs() < 1e-9 && (e - 1.5).abs() < 1e-12);
        let (_, e) = p.closest(30.0, -2.0, 31.0);
        assert!((e + 2.0).abs() < 1e-12);
        assert_eq!(p.point_at(42.0), (42.0, 0.0));
    }

    #[test]
    fn closed_circle_wraps() {
        let r = 40.0;
        let n = 2000;
        let pts = (0..n)
            .map(|i| {
                let t = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
                (r * t.sin(), r - r * t.cos())
            })
            .collect();
        let p = RefPath::new(pts, true);
        assert!((p.length() - 2.0 * std::f64::consts::PI * r).abs() < 0.01);
        // A point just before the start, outside the circle: the offset is to the right (negative).
        let (s, e) = p.closest(-1.0, -0.5, 0.0);
        assert!(s > p.length() - 2.0, "s = {s}");
        assert!(e < 0.0);
    }
    /// Every segment projected, the first strictly closer one kept (what `closest_global` skips
    /// segments against).
    fn brute_closest(p: &RefPath, x: f64, y: f64) -> (f64, f64) {
        let best = (0..p.n_segments()).map(|i| p.project(i, x, y)).fold((f64::INFINITY, 0.0, 0.0), |b, q| {
            if q.0 < b.0 {
                q
            } else {
                b
            }
        });
        (p.wrap(best.1), best.2)
    }

    #[test]
    fn global_search_skips_only_farther_segments() {
        // A wavy open path and a closed circle, queried on a grid around and on them (points on
        // the path itself included: best distance 0).
        let open = RefPath::from_fn(-20.0, 80.0, 0.1, |x| 2.0 * (0.15 * x).sin());
        let circle = RefPath::new(
            (0..500)
                .map(|i| (i as f64 / 500.0 * std::f64::consts::TAU).sin_cos())
                .map(|(s, c)| (30.0 * s, 30.0 * c))
                .collect(),
            true,
        );
        for p in [&open, &circle] {
            for i in -30..=90 {
                for j in -8..=8 {
                    let (x, y) = (i as f64 * 1.37, j as f64 * 4.1);
                    assert_eq!(p.closest_global(x, y), brute_closest(p, x, y), "({x}, {y})");
                }
            }
        }
        let (x, y) = open.point_at(12.34);
        assert_eq!(open.closest_global(x, y), brute_closest(&open, x, y));
    }

    #[test]
    fn preview_start_ahead_gives_the_same_point() {
        let p = RefPath::from_fn(0.0, 50.0, 0.1, |x| (0.2 * x).sin());
        for k in 0..400 {
            let s = k as f64 * 0.123;
            let (want, seg) = p.point_at_from(s, 0, 0);
            // Any start at or before the segment gives the same point; a start beyond it is ignored.
            for ahead in [0, seg / 2, seg, seg + 1, seg + 50, usize::MAX] {
                assert_eq!(p.point_at_from(s, 0, ahead), (want, seg), "s = {s}, ahead = {ahead}");
            }
        }
    }
    #[test]
    fn local_search_matches_a_walk_both_ways() {
        // The walk in both directions from `start` while the next segment is strictly closer
        // (the backward walk from where the forward one ended), written out plainly.
        fn walk(p: &RefPath, x: f64, y: f64, start: usize) -> (f64, f64, usize) {
            let n = p.n_segments();
            let mut best = (start, p.project(start, x, y));
            while best.0 + 1 < n && p.project(best.0 + 1, x, y).0 < best.1 .0 {
                best = (best.0 + 1, p.project(best.0 + 1, x, y));
            }
            while best.0 > 0 && p.project(best.0 - 1, x, y).0 < best.1 .0 {
                best = (best.0 - 1, p.project(best.0 - 1, x, y));
            }
            (best.1 .1, best.1 .2, best.0)
        }
        let p = RefPath::from_fn(0.0, 60.0, 0.1, |x| 3.0 * (0.1 * x).sin());
        for k in 0..300 {
            let (x, y) = (k as f64 * 0.2, 2.5 * (k as f64 * 0.37).cos());
            for start in [0, 10 * (k / 5), 2 * k, 599] {
                assert_eq!(p.closest_from(x, y, start), walk(&p, x, y, start), "({x}, {y}) from {start}");
            }
        }
    }
}
