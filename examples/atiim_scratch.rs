use std::hint::black_box;
use std::path::Path;
use vehsim::contact::spec::ContactSpec;
use vehsim::contact::{ContactTemperature, TyreContact};
fn main() {
    let spec: ContactSpec = toml::from_str("model = \"atiim\"").unwrap();
    let mut est = spec.build_atiim(Path::new("b"), 4, -5.0).unwrap();
    let n = 2_000_000;
    let t0 = std::time::Instant::now();
    let mut acc = 0.0;
    for i in 0..n {
        acc += est.table.rise_k(black_box(4000.0 + (i % 7) as f64), black_box(0.5), black_box(20.0), black_box(-5.0));
    }
    println!("rise_k {:?}/call {acc}", t0.elapsed() / n);
    let tyres = [TyreContact {
        fz_n: 4200.0,
        roll_speed_mps: 20.0,
        slide_speed_mps: 0.3,
        friction_force_n: 500.0,
        surface_temp_c: -5.0,
    }; 4];
    let mut out = [0.0; 4];
    let t0 = std::time::Instant::now();
    for _ in 0..n / 4 {
        est.update(black_box(0.001), black_box(&tyres), &mut out);
    }
    println!("update {:?}/tyre {}", t0.elapsed() / n, out[0]);
    let t0 = std::time::Instant::now();
    let mut a = 0.0;
    for i in 0..n {
        a += black_box(1.0 + i as f64).ln();
    }
    println!("ln {:?} {a}", t0.elapsed() / n);
}
