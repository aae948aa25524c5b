//! Instruction-count harness for one combined-slip tyre evaluation (docs/tyres.md, "Benchmark").
//!
//! `tyre_cost PROVIDER N` builds PROVIDER (a `tyre_model` name) from the SRTT tyre file and calls
//! `forces()` N times through `Arc<dyn TyreModel>` over the 64 inputs of `benches/tyre.rs`
//! (kappa 0.01–0.3, alpha 0.2–0.01 rad, Fz 2–6 kN, mu 0.15, -3 degC ice, contact -1 degC), then
//! prints the sum of the forces. Run it under callgrind with N and with 0; the difference of the
//! instruction counts over N is the cost of one call. A third argument times the prepared path
//! (`TyreModel::forces_prepared`): `load` with each input's own load and surface prepared (a
//! static-load vehicle model), `surface` with the surface prepared at 4 kN and the loads as
//! above (a model with load transfer):
//!
//! ```text
//! cargo build --release --example tyre_cost
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null target/release/examples/tyre_cost pacejka 100000
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null target/release/examples/tyre_cost pacejka 100000 surface
//! ```

use std::hint::black_box;
use std::path::Path;

use vehsim_core::tyre::TyreInput;
use vehsim_core::tyre::TyreModelKind;
use vehsim_spec::tyre::TyreFileSpec;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: tyre_cost PROVIDER N";
    let kind: TyreModelKind = args.get(1).expect(usage).parse().expect("a tyre_model name");
    let n: usize = args.get(2).expect(usage).parse().expect("a call count");
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/vehicles/tyres/srtt_p225_60r16.toml"));
    let model = TyreFileSpec::load(path).and_then(|s| s.build(path, kind)).expect("SRTT provider").model;
    let inputs: Vec<TyreInput> = (0..64)
        .map(|k| {
            let t = k as f64 / 63.0;
            let mut i = TyreInput::new(2000.0 + 4000.0 * t, 0.01 + 0.29 * t * t, 0.2 - 0.19 * t, 0.15);
            i.surface_temp_c = -3.0;
            i.contact_temp_c = -1.0;
            i
        })
        .collect();
    let mode = args.get(3).map(String::as_str);
    let prepared: Vec<_> = inputs
        .iter()
        .map(|i| match mode {
            Some("surface") => model.prepare(&TyreInput { fz_n: 4000.0, ..*i }),
            _ => model.prepare(i),
        })
        .collect();
    let mut sum = 0.0;
    for k in 0..n {
        let f = match mode {
            None => model.forces(black_box(&inputs[k & 63])),
            Some("load" | "surface") => model.forces_prepared(&prepared[k & 63], black_box(&inputs[k & 63])),
            Some(other) => panic!("unknown mode {other}; allowed: load, surface"),
        };
        sum += f.fx_n + f.fy_n + f.mz_nm;
    }
    println!("{sum}");
}
