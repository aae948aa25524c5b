//! Trajectory comparison: two time-series CSV files channel by channel, with per-channel absolute
//! tolerances. The second file is interpolated linearly onto the first file's times (`t_s`), so the
//! two need not share a sampling. Both NaN counts as equal (an empty field, e.g. no speed target
//! while coasting); one NaN against a number is an infinite error. As a guard it is strict:
//! both files' `t_s` must be strictly increasing; the time ranges must overlap by at least
//! [`MIN_OVERLAP`] of the longer one and their ends agree within the `t_s` tolerance (a run that
//! ended earlier or later fails); a channel in only one file fails unless it is ignored by name.
//! `vehsim compare` prints the report (its command: `cli_compare`).

use std::collections::BTreeMap;
use std::path::Path;

use crate::output::num::{sig, Sig};
use crate::output::table::Table;
use vehsim_core::error::{Error, Result};

/// Worst disagreement of one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelError {
    pub channel: String,
    /// Largest |a - b|.
    pub max_abs_error: f64,
    /// Time of that error, s.
    pub at_t_s: f64,
    pub tolerance: f64,
}

impl ChannelError {
    /// Error relative to the tolerance (> 1 means out of tolerance).
    pub fn ratio(&self) -> f64 {
        if self.tolerance > 0.0 {
            self.max_abs_error / self.tolerance
        } else if self.max_abs_error == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }
}

/// Least fraction of the longer time range the two files must share.
pub const MIN_OVERLAP: f64 = 0.99;

/// Result of a comparison: every common channel, worst first.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub channels: Vec<ChannelError>,
    /// Channels present in only one of the files (A's first, then B's).
    pub only_in_one: Vec<String>,
    /// Channels of A missing from B, and of B missing from A.
    pub only_in_a: Vec<String>,
    pub only_in_b: Vec<String>,
    /// First and last `t_s` of A and of B, s.
    pub a_range: (f64, f64),
    pub b_range: (f64, f64),
}

impl Report {
    /// True when every compared channel is within its tolerance.
    pub fn within(&self) -> bool {
        self.channels.iter().all(|c| c.ratio() <= 1.0)
    }
    /// Shared part of the two time ranges as a fraction of the longer one (1 for equal ranges).
    pub fn overlap(&self) -> f64 {
        let (a, b) = (self.a_range, self.b_range);
        let shared = (a.1.min(b.1) - a.0.max(b.0)).max(0.0);
        let longer = (a.1 - a.0).max(b.1 - b.0);
        if longer > 0.0 {
            shared / longer
        } else if a == b {
            1.0
        } else {
            0.0
        }
    }
    /// Channels in only one file and not in `ignore`.
    pub fn missing<'a>(&'a self, ignore: &'a [String]) -> impl Iterator<Item = &'a String> + 'a {
        self.only_in_one.iter().filter(move |c| !ignore.contains(c))
    }
    /// The strict verdict: within tolerance, the ranges overlapping, no channel missing unless ignored.
    pub fn passes(&self, ignore: &[String]) -> bool {
        self.within() && self.overlap() >= MIN_OVERLAP && self.missing(ignore).next().is_none()
    }
    /// The report, one line per channel (t_s first with both ranges, then worst first, then the
    /// missing and ignored channels), for the terminal.
    pub fn lines(&self, ignore: &[String]) -> Vec<String> {
        let mut out = Vec::new();
        let verdict = |ok: bool| if ok { "ok  " } else { "FAIL" };
        for c in &self.channels {
            let ok = c.ratio() <= 1.0;
            if c.channel == "t_s" {
                let ok = ok && self.overlap() >= MIN_OVERLAP;
                out.push(format!(
                    "{} t_s: A {} to {} s, B {} to {} s, overlap {:.1} % (at least {:.0} % needed), ends differ by {} (tolerance {})",
                    verdict(ok),
                    sig(self.a_range.0, 4),
                    sig(self.a_range.1, 4),
                    sig(self.b_range.0, 4),
                    sig(self.b_range.1, 4),
                    100.0 * self.overlap(),
                    100.0 * MIN_OVERLAP,
                    Sig(c.max_abs_error),
                    Sig(c.tolerance)
                ));
            } else {
                out.push(format!(
                    "{} {}: max error {} at t = {} s (tolerance {})",
                    verdict(ok),
                    c.channel,
                    Sig(c.max_abs_error),
                    sig(c.at_t_s, 4),
                    Sig(c.tolerance)
                ));
            }
        }
        for (list, file) in [(&self.only_in_a, "B"), (&self.only_in_b, "A")] {
            for c in list {
                if ignore.contains(c) {
                    out.push(format!("skip {c}: not in {file}; ignored (--ignore)"));
                } else {
                    out.push(format!("FAIL {c}: not in {file} (name it with --ignore to skip it)"));
                }
            }
        }
        out
    }
    /// The channel with the largest error relative to its tolerance.
    pub fn worst(&self) -> Option<&ChannelError> {
        self.channels.iter().min_by(|p, q| q.ratio().total_cmp(&p.ratio()).then_with(|| p.channel.cmp(&q.channel)))
    }
}

/// Parse `channel=value` tolerance arguments.
pub fn parse_tolerances(args: &[String]) -> std::result::Result<BTreeMap<String, f64>, String> {
    let mut m = BTreeMap::new();
    for a in args {
        let (k, v) = a.split_once('=').ok_or_else(|| format!("--tol '{a}': expected channel=value"))?;
        let v: f64 = v.trim().parse().map_err(|_| format!("--tol '{a}': '{v}' is not a number"))?;
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!("--tol '{a}': expected a finite tolerance >= 0"));
        }
        m.insert(k.trim().to_string(), v);
    }
    Ok(m)
}

fn interp(ts: &[f64], ys: &[f64], t: f64) -> f64 {
    let i = ts.partition_point(|v| *v < t);
    if i < ts.len() && ts[i] == t {
        return ys[i];
    }
    if i == 0 || i >= ts.len() {
        return f64::NAN;
    }
    let (t0, t1) = (ts[i - 1], ts[i]);
    let u = (t - t0) / (t1 - t0);
    ys[i - 1] + u * (ys[i] - ys[i - 1])
}

/// Compare table `b` against table `a` (reference) with `tolerances` (absolute, per channel) and
/// `default_tol` for channels not named. `a_path`/`b_path` name the files in errors.
pub fn compare(
    a_path: &Path,
    a: &Table,
    b_path: &Path,
    b: &Table,
    tolerances: &BTreeMap<String, f64>,
    default_tol: f64,
) -> Result<Report> {
    let ta = a.column("t_s").ok_or_else(|| Error::input(a_path, "no 't_s' column"))?;
    let tb = b.column("t_s").ok_or_else(|| Error::input(b_path, "no 't_s' column"))?;
    for (path, t) in [(a_path, ta), (b_path, tb)] {
        if t.is_empty() {
            return Err(Error::input(path, "no rows"));
        }
        if let Some(i) = t.windows(2).position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater)) {
            return Err(Error::input(
                path,
                format!("column 't_s' is not strictly increasing: data row {} has {} after {}", i + 2, t[i + 1], t[i]),
            ));
        }
    }
    for k in tolerances.keys() {
        if a.column(k).is_none() && b.column(k).is_none() {
            return Err(Error::input(a_path, format!("--tol names channel '{k}', which neither file has")));
        }
    }
    let mut channels = Vec::new();
    // The time channel: the ranges must match within the t_s tolerance.
    let t_tol = tolerances.get("t_s").copied().unwrap_or(default_tol);
    let (a0, a1) = (ta.first().copied().unwrap_or(0.0), ta.last().copied().unwrap_or(0.0));
    let (b0, b1) = (tb.first().copied().unwrap_or(0.0), tb.last().copied().unwrap_or(0.0));
    let (dt, at) = if (a0 - b0).abs() > (a1 - b1).abs() { ((a0 - b0).abs(), a0) } else { ((a1 - b1).abs(), a1) };
    channels.push(ChannelError { channel: "t_s".into(), max_abs_error: dt, at_t_s: at, tolerance: t_tol });
    let mut only_in_one = Vec::new();
    for name in &a.columns {
        if name == "t_s" {
            continue;
        }
        let (Some(ya), Some(yb)) = (a.column(name), b.column(name)) else {
            only_in_one.push(name.clone());
            continue;
        };
        let tol = tolerances.get(name).copied().unwrap_or(default_tol);
        let mut worst = ChannelError {
            channel: name.clone(),
            max_abs_error: 0.0,
            at_t_s: ta.first().copied().unwrap_or(0.0),
            tolerance: tol,
        };
        for (t, va) in ta.iter().zip(ya) {
            if *t < b0 || *t > b1 {
                continue;
            }
            let vb = interp(tb, yb, *t);
            let err = match (va.is_nan(), vb.is_nan()) {
                (true, true) => 0.0,
                (false, false) => (va - vb).abs(),
                _ => f64::INFINITY,
            };
            if err > worst.max_abs_error {
                worst.max_abs_error = err;
                worst.at_t_s = *t;
            }
        }
        channels.push(worst);
    }
    let only_in_a = only_in_one.clone();
    let only_in_b: Vec<String> = b.columns.iter().filter(|c| a.column(c).is_none()).cloned().collect();
    only_in_one.extend(only_in_b.iter().cloned());
    channels.sort_by(|p, q| {
        (q.channel == "t_s")
            .cmp(&(p.channel == "t_s"))
            .then(q.ratio().total_cmp(&p.ratio()))
            .then_with(|| p.channel.cmp(&q.channel))
    });
    Ok(Report { channels, only_in_one, only_in_a, only_in_b, a_range: (a0, a1), b_range: (b0, b1) })
}

/// `vehsim compare`: check the flags, compare the files, print one line per channel, the worst
/// channel and the verdict; exit 0 within tolerance, 1 otherwise.
pub(crate) fn cli_compare(
    a: &Path,
    b: &Path,
    tol: &[String],
    default_tol: f64,
    ignore: &[String],
) -> Result<std::process::ExitCode> {
    let tols = parse_tolerances(tol).map_err(|e| Error::usage("--tol", e))?;
    if !(default_tol.is_finite() && default_tol >= 0.0) {
        return Err(Error::usage("--default-tol", "expected a finite tolerance >= 0"));
    }
    let (ta, tb) = match (Table::read(a), Table::read(b)) {
        (Ok(x), Ok(y)) => (x, y),
        (Err(e), _) | (_, Err(e)) => return Err(e),
    };
    let r = compare(a, &ta, b, &tb, &tols, default_tol)?;
    if let Some(c) = ignore.iter().find(|c| ta.column(c).is_none() && tb.column(c).is_none()) {
        return Err(Error::usage("--ignore", format!("names channel '{c}', which neither file has")));
    }
    let lines = r.lines(ignore);
    for line in &lines {
        println!("{line}");
    }
    if let Some(w) = r.worst() {
        println!(
            "worst channel: {} = {} at t = {} s (tolerance {})",
            w.channel,
            Sig(w.max_abs_error),
            sig(w.at_t_s, 4),
            Sig(w.tolerance)
        );
    }
    if r.passes(ignore) {
        println!("within tolerance: {} channels", r.channels.len());
        Ok(std::process::ExitCode::SUCCESS)
    } else {
        let failed = lines.iter().filter(|l| l.starts_with("FAIL")).count();
        println!("FAILED: {failed} of {} lines", r.channels.len() + r.only_in_one.len());
        Ok(std::process::ExitCode::from(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(text: &str) -> Table {
        Table::parse(Path::new("x.csv"), text).unwrap()
    }

    #[test]
    fn identical_passes_and_a_perturbation_is_found_with_its_time() {
        let a = t("t_s,y,z\n0,0,1\n0.1,1,1\n0.2,2,1\n");
        let p = Path::new("a.csv");
        let r = compare(p, &a, p, &a, &BTreeMap::new(), 0.0).unwrap();
        assert!(r.within());
        let b = t("t_s,y,z\n0,0,1\n0.1,1.5,1\n0.2,2,1\n");
        let r = compare(p, &a, p, &b, &BTreeMap::new(), 1e-6).unwrap();
        assert!(!r.within());
        let w = r.worst().unwrap();
        assert_eq!((w.channel.as_str(), w.at_t_s), ("y", 0.1));
        assert!((w.max_abs_error - 0.5).abs() < 1e-12);
        let tol = parse_tolerances(&["y=0.6".to_string()]).unwrap();
        assert!(compare(p, &a, p, &b, &tol, 1e-6).unwrap().within());
    }

    #[test]
    fn interpolates_the_second_file_and_flags_a_shorter_run() {
        let a = t("t_s,y\n0,0\n0.1,1\n0.2,2\n");
        let b = t("t_s,y\n0,0\n0.05,0.5\n0.2,2\n");
        let p = Path::new("a.csv");
        assert!(compare(p, &a, p, &b, &BTreeMap::new(), 1e-12).unwrap().within());
        let short = t("t_s,y\n0,0\n0.1,1\n");
        let r = compare(p, &a, p, &short, &BTreeMap::new(), 1e-9).unwrap();
        assert_eq!(r.worst().unwrap().channel, "t_s");
        assert!(!r.within());
    }
}
