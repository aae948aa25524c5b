//! Reference paths: polylines with arc length, densely sampled, open or closed.

/// Segments per block of [`RefPath::closest_global`]'s bounding boxes.
const BLOCK: usize = 32;

/// A reference path: points (x, y) in the ground frame with cumulative arc length.
#[derive(Debug, Clone, PartialEq)]
pub struct RefPath {
    pts: Vec<(f64, f64)>,
    s: Vec<f64>,
    closed: bool,
    /// Length of each segment, m (hypot of its coordinate differences; the closing segment of a
    /// closed path last), as summed into `s`.
    seg_len: Vec<f64>,
    /// Total length, m ([`RefPath::length`]).
    length: f64,
    /// Per block of [`BLOCK`] consecutive segments, the box (x_lo, x_hi, y_lo, y_hi) around their
    /// end points (NaN coordinates left out: a segment with one has a NaN distance and is never
    /// the closest).
    boxes: Vec<[f64; 4]>,
}

impl RefPath {
    /// Path through `pts` (at least two distinct points). A closed path wraps around.
    pub fn new(pts: Vec<(f64, f64)>, closed: bool) -> Self {
        let n = pts.len();
        let mut s = Vec::with_capacity(n);
        let mut seg_len = Vec::with_capacity(n);
        let mut acc = 0.0;
        for (i, p) in pts.iter().enumerate() {
            if i > 0 {
                let q = pts[i - 1];
                let len = (p.0 - q.0).hypot(p.1 - q.1);
                seg_len.push(len);
                acc += len;
            }
            s.push(acc);
        }
        let mut length = acc;
        if closed && n > 1 {
            let (a, b) = (pts[n - 1], pts[0]);
            let len = (b.0 - a.0).hypot(b.1 - a.1);
            seg_len.push(len);
            length = acc + len;
        }
        let nseg = if closed { n } else { n.saturating_sub(1) };
        let boxes = (0..nseg.div_ceil(BLOCK))
            .map(|k| {
                let mut bx = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
                // the end points of segments k B .. (k + 1) B: points k B ..= (k + 1) B (wrapping)
                for j in k * BLOCK..=((k + 1) * BLOCK).min(nseg) {
                    let p = pts[if j < n { j } else { 0 }];
                    bx = [bx[0].min(p.0), bx[1].max(p.0), bx[2].min(p.1), bx[3].max(p.1)];
                }
                bx
            })
            .collect();
        Self { pts, s, closed, seg_len, length, boxes }
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
        self.length
    }

    /// Arc length at the path's start, m (always 0).
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
        self.point_in(self.index_at(s), s)
    }

    /// The point at arc length `s` on the line of segment `i` (extrapolated beyond its ends).
    fn point_in(&self, i: usize, s: f64) -> (f64, f64) {
        let (a, b, s0) = self.segment(i);
        let len = self.seg_len[i].max(1e-12);
        let u = (s - s0) / len;
        (a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1))
    }

    /// Closest point to (x, y) over the whole path. Returns (arc length, signed lateral offset of
    /// the point, positive to the left of the path direction).
    ///
    /// The first segment (in path order) of the smallest squared distance; segments that cannot be
    /// that close are not projected. A block of segments whose box lies farther than a distance
    /// already found, by a coordinate alone (less a 1 um margin for rounding, squared), is passed
    /// over whole; so is an inner segment (a, b) farther by |x - a_x| - |b_x - a_x| or the same in
    /// y. The threshold is seeded with the block whose box is nearest. Either test skips only
    /// segments strictly farther than one projected, so the answer is that of projecting every
    /// segment. The end segments of an open path extend beyond their ends and are always projected.
    pub fn closest_global(&self, x: f64, y: f64) -> (f64, f64) {
        let nseg = self.n_segments();
        // (squared distance, position along the segment, segment) of the closest so far
        let mut best = (f64::INFINITY, 0.0, 0);
        // Coordinate gap from (x, y) to block k's box, less the margin. (For a NaN query every
        // distance is NaN and nothing is closer than infinity, whatever is passed over.)
        let gap_to = |k: usize| {
            let [x_lo, x_hi, y_lo, y_hi] = self.boxes[k];
            (x_lo - x).max(x - x_hi).max(y_lo - y).max(y - y_hi) - 1e-6
        };
        let blocks = 0..self.boxes.len();
        let nearest = blocks
            .clone()
            .map(|k| (k, gap_to(k)))
            .fold((0, f64::INFINITY), |b, (k, g)| if g < b.1 { (k, g) } else { b });
        let seed = (nearest.0 * BLOCK..((nearest.0 + 1) * BLOCK).min(nseg))
            .map(|i| self.distance(i, x, y).0)
            .fold(f64::INFINITY, f64::min);
        for k in blocks {
            let gap = gap_to(k);
            let end_segment = !self.closed && (k == 0 || (k + 1) * BLOCK >= nseg);
            if !end_segment && gap > 0.0 && gap * gap > best.0.min(seed) {
                continue;
            }
            for i in k * BLOCK..((k + 1) * BLOCK).min(nseg) {
                if self.closed || (i > 0 && i + 1 < nseg) {
                    let (a, b, _) = self.segment(i);
                    let gap = ((x - a.0).abs() - (b.0 - a.0).abs()).max((y - a.1).abs() - (b.1 - a.1).abs()) - 1e-6;
                    if gap > 0.0 && gap * gap > best.0.min(seed) {
                        continue;
                    }
                }
                let (d2, u) = self.distance(i, x, y);
                if d2 < best.0 {
                    best = (d2, u, i);
                }
            }
        }
        // (nothing closer than infinity, e.g. a NaN query: arc length 0 and offset 0, as before)
        let (s, e) = if best.0 < f64::INFINITY { self.place(best.2, best.1, x, y) } else { (0.0, 0.0) };
        (self.wrap(s), e)
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
        // (segment, (squared distance, position along it)); the arc length and offset of the
        // best only.
        let mut best = (start, self.distance(start, x, y));
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
                        let p = self.distance(j, x, y);
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
        let (s, e) = self.place(best.0, best.1 .1, x, y);
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
        (self.point_in(i, s), i)
    }

    /// Projection of (x, y) on segment i: (squared distance, arc length, signed offset). The end
    /// segments of an open path extend beyond their ends.
    #[cfg(test)]
    fn project(&self, i: usize, x: f64, y: f64) -> (f64, f64, f64) {
        let (d2, u) = self.distance(i, x, y);
        let (s, e) = self.place(i, u, x, y);
        (d2, s, e)
    }

    /// The squared distance of (x, y) from segment i and the fraction u along it of the
    /// projection ([`RefPath::project`]'s first part).
    #[inline]
    fn distance(&self, i: usize, x: f64, y: f64) -> (f64, f64) {
        let nseg = self.n_segments();
        let (a, b, _) = self.segment(i);
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
        ((x - px).powi(2) + (y - py).powi(2), u)
    }

    /// The arc length of the point a fraction `u` along segment i and the signed offset of
    /// (x, y) from the segment's line ([`RefPath::project`]'s second part).
    #[inline]
    fn place(&self, i: usize, u: f64, x: f64, y: f64) -> (f64, f64) {
        let (a, b, s0) = self.segment(i);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = (dx * dx + dy * dy).max(1e-24).sqrt();
        (s0 + u * len, (dx * (y - a.1) - dy * (x - a.0)) / len)
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
        // Ties: a path out along y = 0 and back along y = 2 (many blocks apart), queried on
        // y = 1 (exactly as far from both legs: the first, outbound, segment wins) and on the
        // vertices of a straight line (two segments at distance 0).
        let mut pts: Vec<(f64, f64)> = (0..=500).map(|i| (0.1 * i as f64, 0.0)).collect();
        pts.extend((0..=500).rev().map(|i| (0.1 * i as f64, 2.0)));
        let hairpin = RefPath::new(pts, false);
        let line = RefPath::from_fn(0.0, 100.0, 0.5, |_| 0.0);
        for k in -10..=600 {
            let x = 0.1 * k as f64;
            for (p, y) in [(&hairpin, 1.0), (&hairpin, 0.7), (&hairpin, -3.0), (&line, 0.0), (&line, 0.25)] {
                assert_eq!(p.closest_global(x, y), brute_closest(p, x, y), "({x}, {y})");
            }
        }
        // A non-finite query: nothing is closer than infinity (arc length 0, offset 0, as brute force).
        for (x, y) in [(f64::NAN, 1.0), (1.0, f64::NAN), (f64::INFINITY, 0.0)] {
            assert_eq!(open.closest_global(x, y), brute_closest(&open, x, y));
            assert_eq!(open.closest_global(x, y), (0.0, 0.0));
        }
    }

    /// Arc lengths, lengths and points from the stored segment lengths are those of the
    /// coordinate differences (hypot) at every use.
    #[test]
    fn stored_segment_lengths_are_the_hypot_of_the_segment() {
        let circle =
            RefPath::new((0..77).map(|i| (3.0 * (0.1 * i as f64).cos(), 2.0 * (0.1 * i as f64).sin())).collect(), true);
        let open = RefPath::from_fn(-3.0, 7.0, 0.37, |x| (0.4 * x).sin());
        for p in [&circle, &open] {
            for i in 0..p.n_segments() {
                let (a, b, _) = p.segment(i);
                assert_eq!(p.seg_len[i].to_bits(), (b.0 - a.0).hypot(b.1 - a.1).to_bits());
            }
        }
        let (a, b) = (circle.pts[0], circle.pts[76]);
        assert_eq!(circle.length(), circle.s[76] + (a.0 - b.0).hypot(a.1 - b.1));
        assert_eq!(open.length(), *open.s.last().unwrap());
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
