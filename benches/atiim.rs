//! ATIIM benchmarks: the full patch model on a 64 x 48 grid (target <= 2 ms) and the per-step
//! estimator per tyre (target < 200 ns). Run with
//! `cargo bench --bench atiim -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use vehsim_core::contact::model::{solve_patch_at, Kinematics, PatchParams};
use vehsim_core::contact::patch::{synthesize, SynthInputs, TreadPattern};
use vehsim_core::contact::TyreContact;
use vehsim_spec::contact::ContactSpec;

fn grid(load: f64) -> vehsim_core::contact::patch::PressureGrid {
    synthesize(
        Path::new("bench"),
        &SynthInputs {
            load_n: load,
            inflation_pa: 241.3e3,
            tread_width_m: 0.18,
            rated_load_n: 7000.0,
            camber_deg: 0.0,
            pattern: TreadPattern { ribs: 5, void_ratio: 0.3, block_pitch_m: 0.03 },
            rows: 64,
            cols: 48,
        },
    )
    .expect("valid synthetic patch")
}

fn bench(c: &mut Criterion) {
    let g = grid(7000.0);
    let pp = PatchParams::srtt(-3.0);
    // wet case (Fig. 4.9 inputs: 25 m/s, 10 % driving slip, -3 degC), dry case (20 m/s, 1 % slip,
    // -10 degC) and the rig (7 cm/s, 10 % slip, -10 degC)
    let k =
        |v: f64, s: f64, t: f64| Kinematics { travel_speed_mps: v, slip_ratio: s, slip_angle_rad: 0.0, ice_temp_c: t };
    let (wet, dry, rig) = (k(25.0, 0.10, -3.0), k(20.0, 0.01, -10.0), k(0.07, 0.10, -10.0));
    let mut pp_rig = PatchParams::srtt(-10.0);
    pp_rig.lock_time_s = 10.0;
    c.bench_function("patch_64x48_wet_7kN", |b| b.iter(|| black_box(solve_patch_at(black_box(&g), &wet, &pp))));
    c.bench_function("patch_64x48_dry_7kN", |b| b.iter(|| black_box(solve_patch_at(black_box(&g), &dry, &pp))));
    c.bench_function("patch_64x48_rig_7kN", |b| b.iter(|| black_box(solve_patch_at(black_box(&g), &rig, &pp_rig))));

    let spec: ContactSpec = toml::from_str("model = \"atiim\"").expect("valid spec");
    let t0 = std::time::Instant::now();
    let mut est = spec.build_atiim(Path::new("bench.toml"), 4, -5.0).expect("table builds");
    eprintln!("estimator table build: {:?}", t0.elapsed());
    let tyres = [
        TyreContact {
            fz_n: 4200.0,
            roll_speed_mps: 20.0,
            slide_speed_mps: 0.3,
            friction_force_n: 500.0,
            surface_temp_c: -5.0,
        },
        TyreContact {
            fz_n: 3900.0,
            roll_speed_mps: 19.5,
            slide_speed_mps: 0.8,
            friction_force_n: 550.0,
            surface_temp_c: -5.0,
        },
        TyreContact {
            fz_n: 3600.0,
            roll_speed_mps: 20.5,
            slide_speed_mps: 0.1,
            friction_force_n: 300.0,
            surface_temp_c: -5.0,
        },
        TyreContact {
            fz_n: 3300.0,
            roll_speed_mps: 21.0,
            slide_speed_mps: 1.5,
            friction_force_n: 480.0,
            surface_temp_c: -5.0,
        },
    ];
    let mut out = [0.0; 4];
    use vehsim_core::contact::ContactTemperature;
    c.bench_function("estimator_update_4_tyres", |b| {
        b.iter(|| {
            est.update(black_box(0.001), black_box(&tyres), &mut out);
            black_box(out[0])
        })
    });
    let rg = vehsim_core::contact::estimator::TableRanges::default();
    let tb = vehsim_core::contact::estimator::TyreBuild {
        inflation_pa: 241.3e3,
        tread_width_m: 0.18,
        rated_load_n: 7000.0,
        pattern: TreadPattern { ribs: 5, void_ratio: 0.3, block_pitch_m: 0.03 },
        params: pp,
    };
    let mut g = c.benchmark_group("table");
    g.sample_size(10);
    g.bench_function("flash_table_build", |b| {
        b.iter(|| {
            black_box(vehsim_core::contact::estimator::FlashTable::build(Path::new("b"), &tb, &rg).expect("builds"))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
