//! Nanoseconds per combined-slip force evaluation of every tyre provider.
//!
//! Run: `cargo bench --bench tyre -- --warm-up-time 1 --measurement-time 2`
//! Each iteration evaluates one input from a small ring of combined-slip inputs (kappa 0.01–0.3,
//! alpha 0.01–0.2 rad, Fz 2–6 kN, mu 0.15, Delta-T 2 K), so branch prediction cannot lock onto one
//! point. The `reference` group times one libm `atan`, `sin`, `sin_cos`, `tan`, `pow`, `exp`, a
//! `sqrt` and a block of 64 multiply-adds: the Magic Formula with non-zero curvature E needs four
//! atan and two sin per Fx/Fy pair, and those dominate its time; the physical floor of a DLC run
//! (docs/performance.md) is counted in these operations.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use vehsim_core::tyre::TyreInput;
use vehsim_core::tyre::TyreModelKind;
use vehsim_spec::tyre::TyreFileSpec;

fn inputs() -> Vec<TyreInput> {
    (0..64)
        .map(|k| {
            let t = k as f64 / 63.0;
            let mut i = TyreInput::new(2000.0 + 4000.0 * t, 0.01 + 0.29 * t * t, 0.2 - 0.19 * t, 0.15);
            i.surface_temp_c = -3.0;
            i.contact_temp_c = -1.0;
            i
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/vehicles/tyres/srtt_p225_60r16.toml"));
    let spec = TyreFileSpec::load(path).expect("SRTT tyre file");
    let inputs = inputs();
    let mut g = c.benchmark_group("combined_slip_forces");
    let mut variants: Vec<(String, TyreFileSpec, TyreModelKind)> =
        TyreModelKind::ALL.iter().map(|&k| (k.as_str().to_string(), spec.clone(), k)).collect();
    let mut ell = spec.clone();
    ell.pacejka.as_mut().expect("[pacejka] section").combined = "ellipse".into();
    variants.push(("pacejka_ellipse".into(), ell, TyreModelKind::Pacejka));
    let mut mz = spec.clone();
    mz.pacejka.as_mut().expect("[pacejka] section").aligning_moment = true;
    variants.push(("pacejka_with_mz".into(), mz, TyreModelKind::Pacejka));
    for (label, s, kind) in variants {
        let model = s.build(path, kind).expect("provider builds").model;
        let mut k = 0usize;
        g.bench_function(label, |b| {
            b.iter(|| {
                k = (k + 1) & 63;
                black_box(model.forces(black_box(&inputs[k])))
            })
        });
    }
    g.finish();
    // Calibration: one libm call, to scale the numbers above to another (or a less loaded) machine.
    let mut g = c.benchmark_group("reference");
    let xs: Vec<f64> = (0..64).map(|k| 0.05 + 0.1 * k as f64).collect();
    let mut k = 0usize;
    g.bench_function("libm_atan", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            black_box(black_box(xs[k]).atan())
        })
    });
    g.bench_function("libm_sin", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            black_box(black_box(xs[k]).sin())
        })
    });
    // The other operations the physical floor of a run is counted in (docs/performance.md).
    g.bench_function("libm_sin_cos", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            black_box(black_box(xs[k]).sin_cos())
        })
    });
    g.bench_function("libm_tan", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            black_box(black_box(xs[k]).tan())
        })
    });
    g.bench_function("libm_pow", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            black_box(black_box(xs[k]).powf(0.8))
        })
    });
    g.bench_function("libm_exp", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            black_box(black_box(xs[k]).exp())
        })
    });
    g.bench_function("sqrt", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            black_box(black_box(xs[k]).sqrt())
        })
    });
    // 64 multiply-adds in four independent chains: the throughput cost of the plain arithmetic.
    g.bench_function("flops_64", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            let x = black_box(xs[k]);
            let mut acc = [x, x + 1.0, x + 2.0, x + 3.0];
            for _ in 0..16 {
                for a in acc.iter_mut() {
                    *a = *a * 0.999 + 0.001;
                }
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
