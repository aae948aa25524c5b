//! The ATIIM tyre the flash-table tests share: the SRTT build and its full-model rise on the
//! 64 x 48 reference grid.

use std::path::Path;

use vehsim_core::contact::estimator::{Statistic, TyreBuild, REFERENCE_GRID};
use vehsim_core::contact::model::{solve_patch, Operating, PatchParams};
use vehsim_core::contact::patch::{synthesize, PressureGrid, SynthInputs, TreadPattern};

/// The SRTT as the flash table sees it: 241.3 kPa (35 psi), 180 mm tread, 7 kN rated load, five
/// ribs with 30 % void and a 30 mm block pitch; `params` for the friction and heat laws.
pub fn srtt_build(params: PatchParams) -> TyreBuild {
    TyreBuild {
        inflation_pa: 241.3e3,
        tread_width_m: 0.18,
        rated_load_n: 7000.0,
        pattern: TreadPattern { ribs: 5, void_ratio: 0.3, block_pitch_m: 0.03 },
        params,
    }
}

/// The pressure grid of `tb` at load `fz_n` (N), no camber, on the reference grid.
pub fn reference_grid(tb: &TyreBuild, fz_n: f64) -> PressureGrid {
    synthesize(
        Path::new("t"),
        &SynthInputs {
            load_n: fz_n,
            inflation_pa: tb.inflation_pa,
            tread_width_m: tb.tread_width_m,
            rated_load_n: tb.rated_load_n,
            camber_deg: 0.0,
            pattern: tb.pattern,
            rows: REFERENCE_GRID.0,
            cols: REFERENCE_GRID.1,
        },
    )
    .unwrap()
}

/// The full model's contact rise (K, statistic `stat`) on grid `g` of `tb` at sliding speed `vs`,
/// rolling speed `vr` (m/s) and ice temperature `t` (degC).
pub fn full_rise(g: &PressureGrid, tb: &TyreBuild, vs: f64, vr: f64, t: f64, stat: Statistic) -> f64 {
    let op = Operating { roll_speed_mps: vr, slide_speed_mps: vs, ice_temp_c: t };
    stat.of(&solve_patch(g, &op, &tb.params).summary)
}
