//! The coupled patch model: per pixel, one friction law from which the shear stress and the heat
//! both follow, the temperature rise, wet/dry state and water film, marching each track from the
//! leading edge (dissertation §4.1–4.1.5).
//!
//! Kinematics ([`Kinematics`]): travel speed V of the wheel centre over the ice, slip ratio
//! kappa = (omega R - V_x) / V_x with V_x = V cos alpha (> 0 driving, < 0 braking, -1 locked) and
//! slip angle alpha. The tread passes through the patch at the rolling speed v_r = omega R =
//! V_x (1 + kappa); the sliding velocity of tread over ice is (kappa V_x, -V sin alpha), of
//! magnitude v_s. The ice passes at the travel speed V: its contact time at distance x behind the
//! leading edge is x / V (capped at the lock time); the tread's is x / v_r (same cap). Braking and
//! driving at the same |kappa| therefore differ in v_r, v_s and contact times, and in the sign of
//! the longitudinal force.
//!
//! Per track (one column of the grid), pixel by pixel:
//! 1. Brush adhesion: tread and the belt/carcass compliance inside the patch act as springs in
//!    series per unit area, 1/k = 1/k_tread + 1/k_carcass (`Compound::brush_stiffness_pa_per_m`,
//!    [`PatchParams::carcass_stiffness_pa_per_m`]), which sets the steady-state slip stiffness (the
//!    tyre's structural value, [`SRTT_CARCASS_N_PER_M`]). An element at distance xi behind the track's
//!    first loaded pixel carries k sigma xi (sigma = v_s / v_r, the theoretical slip); it sticks
//!    until that reaches the static (peak) friction times p and slides from there on (simple brush
//!    model, sub-pixel onset). The stress points against the sliding velocity (isotropic brush).
//! 2. Dry sliding pixel: tau = mu_dry(T, v_s, p) p with [`IceFriction`], T the interface
//!    temperature left by the earlier pixels; heat q = tau v_s.
//! 3. Rolling (hysteresis) heat in every loaded pixel: the rolling-resistance power f_rr F_z V,
//!    distributed like the pressure, is released through the tread depth d; during the tread's
//!    contact time t only the layer within the thermal penetration depth sqrt(a_tread t) reaches the
//!    interface, so q_roll = f_rr p V min(1, sqrt(a_tread t) / d) (a few per mille at road speed,
//!    about 5 % at the rig's 7 cm/s). The rest warms the tread's bulk (the estimator's bulk state;
//!    over a rig run, [`super::tread_bulk`]).
//! 4. If the interface would reach 0 degC by the pixel's end, the pixel is wet: the interface is
//!    pinned at 0 degC, the conducted flux q_c keeps the Duhamel sum at (0 - T_ice) at the pixel end
//!    (discrete Abel inversion, clamped >= 0), and the film grows from the friction heat of
//!    `WetFilm` (eq. 2.1 with the viscous friction of eq. 4.13 as its floor) plus the rolling
//!    heat minus q_c, and thins by squeeze-out (`film::advance_wet`). The stress is the pixel mean
//!    of that law, so the heat is exactly tau v_s there as well.
//!
//! Patch forces: F_x = sum(tau_x dA), F_y = sum(tau_y dA); `drawbar_coeff` = F_x / F_z (signed:
//! > 0 driving), `friction_coeff` = |F| / F_z.

use super::film::{advance_wet, FilmCoeffs, FilmParams};
use super::heat::{centre_weights, duhamel_weights, effective_effusivity};
use super::patch::PressureGrid;
use super::thermal::{Compound, ICE, MELT_C, WATER_VISCOSITY_PA_S};
use crate::tyre::friction::{beta_from_critical_height, IceFriction, WetFilm};
use std::f64::consts::PI;

/// Reference inflation pressure of the in-patch carcass stiffness, Pa (the SRTT's 35 psi).
pub(crate) const CARCASS_REF_INFLATION_PA: f64 = 241.3e3;

/// Parameters of the patch model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchParams {
    /// Tread compound (thermal properties, Shore A).
    pub compound: Compound,
    /// Dry rubber-ice friction at the reference conditions of [`IceFriction`], 0.02–0.6
    /// (the scenario's `mu_dry`; equal to `dry.mu_ref`).
    pub mu_dry: f64,
    /// Dry rubber-ice friction law.
    pub dry: IceFriction,
    /// Water-film parameters.
    pub film: FilmParams,
    /// Critical film height of eq. 2.1 (excess friction down to 25 %), m (20e-9 – 1e-6).
    pub critical_film_m: f64,
    /// Tread depth, m (0.002–0.010; SRTT 7.97 mm), for the brush stiffness.
    pub tread_depth_m: f64,
    /// Void ratio used for the brush stiffness, 0–0.6.
    pub void_ratio: f64,
    /// Brush adhesion zone on (true) or the whole patch sliding (false).
    pub brush: bool,
    /// Contact-time cap, s (locked wheel: the lock duration; 0.1–10).
    pub lock_time_s: f64,
    /// In-patch belt and carcass compliance as a longitudinal spring shared by the contact area, N/m,
    /// at the inflation below ([`SRTT_CARCASS_N_PER_M`]); 0 = rigid.
    pub carcass_n_per_m: f64,
    /// Rolling-resistance coefficient f_rr (0–0.05) for the hysteresis heat.
    pub rolling_resistance: f64,
}

impl PatchParams {
    /// SRTT defaults used by the shipped scenarios (each documented in docs/atiim.md).
    pub fn srtt(ice_temp_c: f64) -> Self {
        PatchParams {
            compound: Compound::generic(super::thermal::preset_shore_a("srtt", ice_temp_c).unwrap_or(67.3)),
            mu_dry: 0.15,
            dry: IceFriction::srtt(0.15),
            film: FilmParams { kappa: 1.0, asperity_d_m: super::film::DEFAULT_ASPERITY_D_M, substeps: 8 },
            critical_film_m: 50e-9,
            tread_depth_m: 7.97e-3,
            void_ratio: 0.3,
            brush: true,
            lock_time_s: 1.0,
            carcass_n_per_m: carcass_stiffness_n_per_m(SRTT_CARCASS_N_PER_M, CARCASS_REF_INFLATION_PA),
            rolling_resistance: 0.010,
        }
    }

    /// The same parameters with a constant friction `mu` (no rolling heat): the classic model.
    pub fn with_constant_friction(mut self, mu: f64) -> Self {
        self.mu_dry = mu;
        self.dry = IceFriction::constant(mu);
        self.rolling_resistance = 0.0;
        self
    }

    /// Carcass stiffness per unit contact area, Pa/m, for a patch of area `area_m2`: the carcass
    /// spring shared by the elements in contact (infinite if `carcass_n_per_m` is 0).
    pub fn carcass_stiffness_pa_per_m(&self, area_m2: f64) -> f64 {
        if self.carcass_n_per_m > 0.0 && area_m2 > 0.0 {
            self.carcass_n_per_m / area_m2
        } else {
            f64::INFINITY
        }
    }

    /// Brush stiffness per unit area, Pa/m: tread and carcass in series.
    pub fn series_stiffness_pa_per_m(&self, area_m2: f64) -> f64 {
        let kt = self.compound.brush_stiffness_pa_per_m(self.tread_depth_m, self.void_ratio);
        let kc = self.carcass_stiffness_pa_per_m(area_m2);
        if kc.is_finite() {
            kt * kc / (kt + kc)
        } else {
            kt
        }
    }
}

/// SRTT in-patch belt and carcass compliance at 241.3 kPa, as a spring of N/m shared by the contact
/// area, set so that the patch's steady-state longitudinal slip stiffness at 7 kN, 35 psi and
/// -10 degC is the tyre's structural value, 22 F_z (the SRTT Magic Formula file's PKX1, a
/// passenger-tyre magnitude: 15–25 F_z). The slip stiffness at kappa -> 0 is a property of the
/// structure, not of the friction (brush theory: the whole patch adheres). The lumped rim-to-belt
/// carcass spring (a few hundred kN/m; 22 F_z x 4 kN / 0.15 m relaxation length = 590 kN/m for the
/// car's SRTT) does not enter here: a rigid belt displaced as a whole rolls at the rim's angular
/// speed, so in steady state it changes the relaxation length, not the slip stiffness. (Until
/// issue 29 this was 600 kN/m, which put the slip stiffness at 6 F_z.)
pub const SRTT_CARCASS_N_PER_M: f64 = 3600e3;

/// Carcass stiffness at inflation `inflation_pa` from its value `at_ref_n_per_m` at
/// `CARCASS_REF_INFLATION_PA`: proportional to the inflation pressure (assumption: the
/// carcass's stiffness is the tension of the inflated membrane, which scales with pressure).
pub fn carcass_stiffness_n_per_m(at_ref_n_per_m: f64, inflation_pa: f64) -> f64 {
    at_ref_n_per_m * inflation_pa / CARCASS_REF_INFLATION_PA
}

/// Operating point of the patch in the engine's terms (rolling and sliding speed magnitudes).
/// Read as straight-line braking ([`Kinematics::from`]): travel speed = roll + slide, exact for
/// free rolling and a locked wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Operating {
    /// Rolling speed omega R_e of the tread, m/s (>= 0; 0 = locked).
    pub roll_speed_mps: f64,
    /// Sliding speed of tread over ice, m/s (>= 0).
    pub slide_speed_mps: f64,
    /// Bulk ice temperature (and initial tread surface temperature), degC (-30..0).
    pub ice_temp_c: f64,
}

/// Kinematics of the wheel over the ice (see the module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Travel speed V of the wheel centre, m/s (>= 0).
    pub travel_speed_mps: f64,
    /// Slip ratio kappa = (omega R - V_x) / V_x, -1..2 (> 0 driving, < 0 braking).
    pub slip_ratio: f64,
    /// Slip angle alpha, rad (-0.5..0.5): angle of the travel velocity to the wheel plane,
    /// positive toward +y (the lateral sliding of the wheel over the ice is V sin alpha toward +y).
    pub slip_angle_rad: f64,
    /// Bulk ice temperature, degC.
    pub ice_temp_c: f64,
}

impl From<&Operating> for Kinematics {
    fn from(op: &Operating) -> Self {
        let fin = |v: f64| if v.is_finite() { v.max(0.0) } else { 0.0 };
        let (vr, vs) = (fin(op.roll_speed_mps), fin(op.slide_speed_mps));
        let v = vr + vs;
        Kinematics {
            travel_speed_mps: v,
            slip_ratio: if v > 0.0 { -vs / v } else { 0.0 },
            slip_angle_rad: 0.0,
            ice_temp_c: op.ice_temp_c,
        }
    }
}

impl Kinematics {
    /// (rolling speed v_r, longitudinal sliding kappa V_x, lateral sliding V sin alpha), m/s.
    pub fn speeds(&self) -> (f64, f64, f64) {
        let v = if self.travel_speed_mps.is_finite() { self.travel_speed_mps.max(0.0) } else { 0.0 };
        let a = if self.slip_angle_rad.is_finite() { self.slip_angle_rad.clamp(-1.5, 1.5) } else { 0.0 };
        let k = if self.slip_ratio.is_finite() { self.slip_ratio.clamp(-1.0, 10.0) } else { 0.0 };
        let vx = v * a.cos();
        ((vx * (1.0 + k)).max(0.0), k * vx, v * a.sin())
    }

    /// Sliding speed magnitude, m/s.
    pub fn slide_speed_mps(&self) -> f64 {
        let (_, sx, sy) = self.speeds();
        sx.hypot(sy)
    }
}

/// Per-pixel fields and patch summary (row-major like the grid).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PatchResult {
    /// Pixels along travel (row 0 = leading edge), as in the pressure grid.
    pub rows: usize,
    /// Pixels across the width, as in the pressure grid.
    pub cols: usize,
    /// Temperature rise of the interface at pixel centres, K (capped at 0 degC - T_ice).
    pub rise_k: Vec<f64>,
    /// Wet (melting) pixels.
    pub wet: Vec<bool>,
    /// Sliding pixels (others adhere or are out of contact).
    pub sliding: Vec<bool>,
    /// Film height at pixel ends, m.
    pub film_m: Vec<f64>,
    /// Viscous friction in wet pixels, else 0: the pixel mean of the wet law's floor
    /// min(mu_v, mu_d), mu_v = kappa eta v / (p h) of eq. 4.13 (eq. 4.13 itself diverges at melting
    /// onset, h -> 0; the floor is capped at the dry friction there).
    pub mu_visc: Vec<f64>,
    /// Friction coefficient carried by each loaded pixel (|tau| / p), else 0.
    pub mu: Vec<f64>,
    /// Part of `mu` carried by sliding (the rest adheres), so that q_friction = mu_slide p v_s.
    pub mu_slide: Vec<f64>,
    /// Heat generated (friction + rolling), of it by rolling hysteresis, into tread, into ice, into
    /// melting (incl. squeezed water), W/m^2.
    pub q_gen: Vec<f64>,
    /// Heat generated by rolling hysteresis per pixel, W/m^2.
    pub q_roll: Vec<f64>,
    /// Heat flowing into the tread per pixel, W/m^2.
    pub q_tread: Vec<f64>,
    /// Heat flowing into the ice per pixel, W/m^2.
    pub q_ice: Vec<f64>,
    /// Heat going into melting per pixel (incl. squeezed-out water), W/m^2.
    pub q_melt: Vec<f64>,
    /// Sliding speed and the unit direction of the stress on the tyre (x, y), used for the forces.
    pub slide_speed_mps: f64,
    /// Unit direction (x, y) of the tangential stress on the tyre, in wheel axes.
    pub force_dir: (f64, f64),
    /// Summary.
    pub summary: PatchSummary,
}

/// Length over which the leading-edge viscous friction is averaged, m (from each track's first
/// wet point).
pub(crate) const LEADING_AVERAGE_M: f64 = 0.01;

/// Length over which the trailing-edge viscous friction and film height are averaged, m (the
/// last part of each track's loaded length).
pub(crate) const TRAILING_AVERAGE_M: f64 = 0.02;

/// Patch maxima and averages.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PatchSummary {
    /// Normal load carried by the grid, N.
    pub load_n: f64,
    /// Loaded (pressure > 0) area, m^2.
    pub contact_area_m2: f64,
    /// Mean pressure over the loaded area, Pa.
    pub mean_pressure_pa: f64,
    /// Largest pixel pressure, Pa.
    pub max_pressure_pa: f64,
    /// Largest interface temperature rise, K.
    pub max_rise_k: f64,
    /// Mean rise over loaded pixels, K (the estimator's flash rise).
    pub mean_rise_k: f64,
    /// Share of loaded pixels that are wet (melting), in [0, 1].
    pub wet_fraction: f64,
    /// Share of loaded pixels that slide, in [0, 1].
    pub sliding_fraction: f64,
    /// Largest water-film height, m.
    pub max_film_m: f64,
    /// Mean film height over wet pixels, m (0 with none wet).
    pub mean_film_wet_m: f64,
    /// Film height averaged over the wet part of the last `TRAILING_AVERAGE_M` of each track, m.
    pub trailing_film_m: f64,
    /// Viscous friction (eq. 4.13), pressure-weighted: averaged over the first
    /// `LEADING_AVERAGE_M` of each track's wet zone (time average of 1/h, which converges under
    /// grid refinement), over the last `TRAILING_AVERAGE_M` of each track (trailing edge), and
    /// the plain mean over wet pixels.
    pub mu_visc_leading: f64,
    /// Viscous friction averaged over the last `TRAILING_AVERAGE_M` of each track (trailing edge), pressure-weighted.
    pub mu_visc_trailing: f64,
    /// Plain mean viscous friction over wet pixels (0 with none wet).
    pub mu_visc_mean: f64,
    /// Longitudinal force over load F_x / F_z (drawbar-pull coefficient; > 0 driving).
    pub drawbar_coeff: f64,
    /// Total tangential force over load |F| / F_z.
    pub friction_coeff: f64,
    /// Lateral force over load F_y / F_z.
    pub lateral_coeff: f64,
    /// Patch powers, W: generated (friction + rolling), friction work sum(tau_slide v_s dA),
    /// rolling hysteresis, into tread, ice, melting.
    pub power_generated_w: f64,
    /// Friction work sum(tau_slide v_s dA), W.
    pub power_friction_w: f64,
    /// Rolling-hysteresis heat, W.
    pub power_rolling_w: f64,
    /// Heat into the tread, W.
    pub power_tread_w: f64,
    /// Heat into the ice, W.
    pub power_ice_w: f64,
    /// Heat into melting, W.
    pub power_melt_w: f64,
}

/// Solve the patch model on `grid` at `op` (read as braking, see [`Operating`]).
pub fn solve_patch(grid: &PressureGrid, op: &Operating, pp: &PatchParams) -> PatchResult {
    solve_patch_at(grid, &Kinematics::from(op), pp)
}

/// Solve the patch model on `grid` for the wheel kinematics `kin`. Never panics; degenerate inputs
/// (zero speeds, non-finite values) give a cold, dry patch.
pub fn solve_patch_at(grid: &PressureGrid, kin: &Kinematics, pp: &PatchParams) -> PatchResult {
    // a grid whose shape does not match its data (possible only when built by hand, since every
    // reader validates) is treated as empty
    let (rows, cols) = if grid.p_pa.len() == grid.rows * grid.cols { (grid.rows, grid.cols) } else { (0, 0) };
    let (vr, sx, sy) = kin.speeds();
    let vs = sx.hypot(sy);
    let mut r = PatchResult::cold(rows, cols, (sx, sy), vs);
    let t = TrackSetup::new(grid, kin, pp, (rows, cols), vr, vs);
    let mut q = vec![0.0; rows];
    for c in 0..cols {
        q.iter_mut().for_each(|v| *v = 0.0);
        t.solve_track(c, &mut q, &mut r);
    }
    summarize(grid, &mut r);
    r
}

impl PatchResult {
    /// A cold, dry patch of `rows` x `cols` pixels for the sliding velocity (sx, sy), m/s, of
    /// magnitude `vs`.
    fn cold(rows: usize, cols: usize, (sx, sy): (f64, f64), vs: f64) -> Self {
        let n = rows * cols;
        PatchResult {
            rows,
            cols,
            rise_k: vec![0.0; n],
            wet: vec![false; n],
            sliding: vec![false; n],
            film_m: vec![0.0; n],
            mu_visc: vec![0.0; n],
            mu: vec![0.0; n],
            mu_slide: vec![0.0; n],
            q_gen: vec![0.0; n],
            q_roll: vec![0.0; n],
            q_tread: vec![0.0; n],
            q_ice: vec![0.0; n],
            q_melt: vec![0.0; n],
            slide_speed_mps: vs,
            // the stress on the tyre opposes the tread's sliding over the ice: longitudinal + for
            // driving; lateral against the wheel's sideways travel
            force_dir: if vs > 0.0 { (sx / vs, -sy / vs) } else { (1.0, 0.0) },
            summary: PatchSummary::default(),
        }
    }
}

/// What every track (one column of pixels along travel) of one patch solve shares: the
/// operating point, the heating's time step and weights, and per row the effective effusivity
/// of tread + ice (W s^0.5/(m^2 K)), the tread's share of the interface flux and the rolling
/// heat per unit pressure (W/m^2 per Pa).
struct TrackSetup<'a> {
    grid: &'a PressureGrid,
    pp: &'a PatchParams,
    rows: usize,
    cols: usize,
    heating: bool,
    /// Pixel transit time, s.
    dt: f64,
    /// 2 sqrt(dt / pi), s^0.5.
    k_rise: f64,
    /// Ice temperature and its margin to melting, degC and K.
    tice: f64,
    dtm: f64,
    /// Sliding speed, m/s; slip = sliding / rolling speed.
    vs: f64,
    slip: f64,
    /// Series (tread + carcass) shear stiffness, Pa/m.
    kb: f64,
    /// Film law's decay constant, 1/m.
    beta: f64,
    wend: Vec<f64>,
    wc: Vec<f64>,
    e_row: Vec<f64>,
    ft_row: Vec<f64>,
    roll_row: Vec<f64>,
}

/// One contact pixel of a track: its index in the grid, its row, pressure (Pa), sliding
/// fraction, adhesion stress (Pa) and rolling heat (W/m^2).
struct Pixel {
    idx: usize,
    row: usize,
    p: f64,
    frac: f64,
    tau_adh: f64,
    q_roll: f64,
}

impl<'a> TrackSetup<'a> {
    /// The shared part of a solve on `grid` (`rows` x `cols` used) at rolling speed `vr` and
    /// sliding speed `vs`, m/s.
    fn new(
        grid: &'a PressureGrid,
        kin: &Kinematics,
        pp: &'a PatchParams,
        (rows, cols): (usize, usize),
        vr: f64,
        vs: f64,
    ) -> Self {
        let v = if kin.travel_speed_mps.is_finite() { kin.travel_speed_mps.max(0.0) } else { 0.0 };
        let tice = if kin.ice_temp_c.is_finite() { kin.ice_temp_c } else { MELT_C };
        let lock = pp.lock_time_s.max(1e-6);
        // ice transit speed: the travel speed, but the ice stays at most the lock time under the patch
        let vg = v.max(rows as f64 * grid.dx_m / lock);
        let dtm = (MELT_C - tice).max(0.0);
        let e_t = pp.compound.solid.effusivity();
        let e_i = ICE.effusivity();
        let kb = pp.series_stiffness_pa_per_m(grid.contact_area_m2());
        let slip = if vr > 1e-9 { vs / vr } else { f64::INFINITY };
        let beta = beta_from_critical_height(pp.critical_film_m);
        let f_rr = pp.rolling_resistance.max(0.0);
        let heating = vg > 1e-9 && (vs > 0.0 || (f_rr > 0.0 && v > 0.0));
        let dt = if heating { grid.dx_m / vg } else { 0.0 };
        let wend = duhamel_weights(rows + 1);
        let wc = centre_weights(rows + 1);
        // Effective effusivity and tread share per row (same for every track).
        let mut e_row = vec![e_t + e_i; rows];
        let mut ft_row = vec![e_t / (e_t + e_i); rows];
        let mut roll_row = vec![0.0; rows];
        if heating {
            for i in 0..rows {
                let x = (i as f64 + 0.5) * grid.dx_m;
                let ti = x / vg;
                let tt = if vr > 1e-12 { (x / vr).min(lock) } else { lock };
                e_row[i] = effective_effusivity(e_t, e_i, ti, tt);
                ft_row[i] = (e_row[i] - e_i) / e_row[i];
                roll_row[i] = f_rr * v * rolling_heat_share(&pp.compound, pp.tread_depth_m, tt);
            }
        }
        let k_rise = 2.0 * dt.sqrt() / PI.sqrt();
        TrackSetup {
            grid,
            pp,
            rows,
            cols,
            heating,
            dt,
            k_rise,
            tice,
            dtm,
            vs,
            slip,
            kb,
            beta,
            wend,
            wc,
            e_row,
            ft_row,
            roll_row,
        }
    }

    /// Solve track `c` from the leading edge, writing its pixels into `r`; `q` (W/m^2 per row,
    /// zeroed) collects the interface fluxes whose history heats the pixels behind. (The history
    /// sums index three arrays at k and i - k: a range loop.)
    #[allow(clippy::needless_range_loop)]
    fn solve_track(&self, c: usize, q: &mut [f64], r: &mut PatchResult) {
        let (grid, pp, cols) = (self.grid, self.pp, self.cols);
        let (heating, k_rise, tice, dtm, vs) = (self.heating, self.k_rise, self.tice, self.dtm, self.vs);
        let mut first: Option<usize> = None;
        let mut sliding = !pp.brush;
        let mut h = 0.0f64;
        let mut wet_prev = false;
        for i in 0..self.rows {
            let idx = i * cols + c;
            let p = grid.p_pa[i * grid.cols + c];
            // history sums of earlier pixels: at this pixel's end and centre
            let (mut s_end, mut s_mid) = (0.0, 0.0);
            if heating {
                for k in 0..i {
                    s_end += q[k] * self.wend[i - k];
                    s_mid += q[k] * self.wc[i - k];
                }
            }
            let e = self.e_row[i];
            if p <= 0.0 {
                // groove or outside: no contact, no heat; water stays in place
                r.rise_k[idx] = if heating { (k_rise * s_mid / e).min(dtm) } else { 0.0 };
                r.film_m[idx] = h;
                continue;
            }
            // interface temperature this pixel starts from (earlier pixels' heat)
            let t_loc = tice + if heating { (k_rise * s_mid / e).min(dtm) } else { 0.0 };
            let i0 = *first.get_or_insert(i);
            let xi = (i - i0) as f64 * grid.dx_m + 0.5 * grid.dx_m;
            // Fraction of this pixel's length that slides: the onset xi_s = mu_s p / (k s) may fall
            // inside the pixel (sub-pixel onset keeps the result continuous in the slip).
            let mut frac = 1.0;
            let mut tau_adh = 0.0;
            if !sliding {
                (frac, tau_adh) = self.adhesion(t_loc, p, xi);
                sliding = frac > 0.0;
            }
            let q_roll = self.roll_row[i] * p;
            r.q_roll[idx] = q_roll;
            r.sliding[idx] = frac > 0.0;
            let mu_k = pp.dry.mu(t_loc, vs, p);
            let q_dry = frac * mu_k * p * vs + q_roll;
            let rise_end_dry = k_rise * (s_end + q_dry * self.wend[0]) / e;
            if !heating || (!(wet_prev || h > 0.0) && rise_end_dry < dtm) || frac == 0.0 && h <= 0.0 {
                q[i] = q_dry;
                r.rise_k[idx] = if heating { (k_rise * (s_mid + q_dry * self.wc[0]) / e).min(dtm) } else { 0.0 };
                r.mu_slide[idx] = frac * mu_k;
                r.mu[idx] = (frac * mu_k * p + (1.0 - frac) * tau_adh) / p;
                if heating {
                    r.q_gen[idx] = q_dry;
                    r.q_tread[idx] = self.ft_row[i] * q_dry;
                    r.q_ice[idx] = q_dry - r.q_tread[idx];
                }
                continue;
            }
            // wet: pin the interface at the melting point at the pixel end
            let px = Pixel { idx, row: i, p, frac, tau_adh, q_roll };
            let (q_cond, h_end) = self.wet_pixel(&px, h, s_end, r);
            q[i] = q_cond;
            h = h_end;
            wet_prev = h > 0.0;
        }
    }

    /// Fraction of a pixel's length that slides, and the mean adhesion stress over the part
    /// that adheres, Pa, for a pixel centred `xi` (m) behind the track's first contact at
    /// interface temperature `t_loc` (degC) and pressure `p` (Pa). The brush's sliding onset
    /// xi_s = mu_s p / (k s) may fall inside the pixel (the sub-pixel onset keeps the result
    /// continuous in the slip).
    fn adhesion(&self, t_loc: f64, p: f64, xi: f64) -> (f64, f64) {
        let dx = self.grid.dx_m;
        let mu_s = self.pp.dry.static_mu(t_loc, p);
        let xi_s =
            if self.slip.is_finite() && self.slip > 0.0 { mu_s * p / (self.kb * self.slip) } else { f64::INFINITY };
        let x_lo = xi - 0.5 * dx;
        let xi_end = xi + 0.5 * dx;
        let frac = if self.slip.is_finite() { ((xi_end - xi_s) / dx).clamp(0.0, 1.0) } else { 1.0 };
        // mean adhesion stress over the adhering part of the pixel
        let xa = 0.5 * (x_lo + xi_end.min(xi_s.max(x_lo)));
        let tau_adh = (self.kb * self.slip.min(1e6) * xa.max(0.0)).min(mu_s * p);
        (frac, tau_adh)
    }

    /// A pixel whose interface reaches melting: the water film over the pixel's transit with the
    /// interface pinned at 0 degC at the pixel end; writes the pixel into `r` and returns the
    /// flux conducted into tread and ice (W/m^2) and the film thickness at the pixel end (m).
    /// `h`: film thickness at entry, m; `s_end`: the history sum at the pixel end.
    fn wet_pixel(&self, px: &Pixel, h: f64, s_end: f64, r: &mut PatchResult) -> (f64, f64) {
        let (pp, vs, dtm, k_rise) = (self.pp, self.vs, self.dtm, self.k_rise);
        let e = self.e_row[px.row];
        let qc = ((dtm * e / k_rise - s_end) / self.wend[0]).max(0.0);
        let law = WetFilm {
            pv: px.frac * px.p * vs,
            mu_d: pp.dry.mu(MELT_C, vs, px.p),
            beta: self.beta,
            visc_m: pp.film.kappa * WATER_VISCOSITY_PA_S * vs / px.p,
        };
        let c_sq = FilmCoeffs::new(&pp.film, vs, qc, px.p).c;
        let st = advance_wet(h, self.dt, pp.film.substeps, &law, px.q_roll, qc, c_sq);
        let q_f = st.friction_j_m2 / self.dt;
        let q_cond = st.conducted_j_m2 / self.dt;
        r.wet[px.idx] = true;
        r.rise_k[px.idx] = dtm;
        r.film_m[px.idx] = st.h_end_m;
        r.mu_visc[px.idx] = st.viscous_mu_integral / self.dt;
        let mu_wet = if vs > 0.0 { q_f / (px.p * vs) } else { 0.0 };
        r.mu_slide[px.idx] = mu_wet;
        r.mu[px.idx] = mu_wet + (1.0 - px.frac) * px.tau_adh / px.p;
        r.q_gen[px.idx] = q_f + px.q_roll;
        r.q_tread[px.idx] = self.ft_row[px.row] * q_cond;
        r.q_ice[px.idx] = q_cond - r.q_tread[px.idx];
        r.q_melt[px.idx] = r.q_gen[px.idx] - q_cond;
        (q_cond, st.h_end_m)
    }
}

fn summarize(grid: &PressureGrid, r: &mut PatchResult) {
    let da = grid.pixel_area_m2();
    let (rows, cols) = (r.rows, r.cols);
    let mut s = PatchSummary {
        load_n: grid.load_n(),
        contact_area_m2: grid.contact_area_m2(),
        mean_pressure_pa: grid.mean_contact_pressure_pa(),
        max_pressure_pa: grid.p_pa.iter().cloned().fold(0.0, f64::max),
        ..Default::default()
    };
    let (mut nl, mut nw, mut ns) = (0usize, 0usize, 0usize);
    let (mut sum_rise, mut sum_film, mut sum_mu_v, mut tau) = (0.0, 0.0, 0.0, 0.0);
    for idx in 0..rows * cols {
        let p = grid.p_pa[idx];
        s.max_rise_k = s.max_rise_k.max(r.rise_k[idx]);
        s.max_film_m = s.max_film_m.max(r.film_m[idx]);
        s.power_generated_w += r.q_gen[idx] * da;
        s.power_rolling_w += r.q_roll[idx] * da;
        s.power_friction_w += r.mu_slide[idx] * p * r.slide_speed_mps * da;
        s.power_tread_w += r.q_tread[idx] * da;
        s.power_ice_w += r.q_ice[idx] * da;
        s.power_melt_w += r.q_melt[idx] * da;
        if p > 0.0 {
            nl += 1;
            sum_rise += r.rise_k[idx];
            tau += r.mu[idx] * p * da;
            if r.sliding[idx] {
                ns += 1;
            }
            if r.wet[idx] {
                nw += 1;
                sum_film += r.film_m[idx];
                sum_mu_v += r.mu_visc[idx];
            }
        }
    }
    // Viscous friction over the first LEADING_AVERAGE_M of each track's wet zone and over the last
    // TRAILING_AVERAGE_M of each track's loaded length (partial pixels by their overlap), pressure-weighted
    // (sum mu p / sum p = shear force / normal force), so low-pressure edge pixels do not dominate.
    let (mut lead_t, mut lead_p) = (0.0, 0.0);
    for c in 0..cols {
        if let Some(f) = (0..rows).find(|&i| r.wet[i * cols + c]) {
            for i in f..rows {
                let x0 = (i - f) as f64 * grid.dx_m;
                if x0 >= LEADING_AVERAGE_M {
                    break;
                }
                let w = ((LEADING_AVERAGE_M - x0) / grid.dx_m).min(1.0);
                let p = grid.p_pa[i * cols + c];
                if r.wet[i * cols + c] {
                    lead_t += w * r.mu_visc[i * cols + c] * p;
                    lead_p += w * p;
                }
            }
        }
    }
    let (t_mu, t_film) = trailing_average(grid, r, TRAILING_AVERAGE_M);
    if lead_p > 0.0 {
        s.mu_visc_leading = lead_t / lead_p;
    }
    s.mu_visc_trailing = t_mu;
    s.trailing_film_m = t_film;
    if nl > 0 {
        s.mean_rise_k = sum_rise / nl as f64;
        s.wet_fraction = nw as f64 / nl as f64;
        s.sliding_fraction = ns as f64 / nl as f64;
    }
    if nw > 0 {
        s.mean_film_wet_m = sum_film / nw as f64;
        s.mu_visc_mean = sum_mu_v / nw as f64;
    }
    if s.load_n > 0.0 {
        s.friction_coeff = tau / s.load_n;
        s.drawbar_coeff = s.friction_coeff * r.force_dir.0;
        s.lateral_coeff = s.friction_coeff * r.force_dir.1;
    }
    r.summary = s;
}

/// Viscous friction (eq. 4.13, pressure-weighted) and film height over the wet part of the last
/// `len_m` of each track's loaded length (partial pixels weighted by their overlap); (0, 0) if
/// nothing there is wet.
pub(crate) fn trailing_average(grid: &PressureGrid, r: &PatchResult, len_m: f64) -> (f64, f64) {
    let (rows, cols) = (r.rows, r.cols);
    let (mut mu_t, mut mu_p, mut film_t, mut film_n) = (0.0, 0.0, 0.0, 0.0);
    for c in 0..cols {
        let Some(i1) = (0..rows).rev().find(|&i| grid.p_pa[i * cols + c] > 0.0) else { continue };
        let x_end = (i1 + 1) as f64 * grid.dx_m;
        for i in (0..=i1).rev() {
            let w = (((i + 1) as f64 * grid.dx_m - (x_end - len_m)) / grid.dx_m).clamp(0.0, 1.0);
            if w <= 0.0 {
                break;
            }
            let idx = i * cols + c;
            let p = grid.p_pa[idx];
            if p > 0.0 && r.wet[idx] {
                mu_t += w * r.mu_visc[idx] * p;
                mu_p += w * p;
                film_t += w * r.film_m[idx];
                film_n += w;
            }
        }
    }
    if mu_p > 0.0 {
        (mu_t / mu_p, film_t / film_n)
    } else {
        (0.0, 0.0)
    }
}

/// Drawbar pull versus slip ratio at travel speed `speed_mps`, slip angle `slip_angle_rad` and ice
/// temperature `ice_temp_c`: the patch solved at each slip ratio kappa (-1..2; > 0 driving).
/// Returns (kappa, summary).
pub fn drawbar_curve(
    grid: &PressureGrid,
    pp: &PatchParams,
    speed_mps: f64,
    slip_angle_rad: f64,
    ice_temp_c: f64,
    slips: &[f64],
) -> Vec<(f64, PatchSummary)> {
    slips
        .iter()
        .map(|&k| {
            let kin = Kinematics { travel_speed_mps: speed_mps, slip_ratio: k, slip_angle_rad, ice_temp_c };
            (k, solve_patch_at(grid, &kin, pp).summary)
        })
        .collect()
}

/// Share of the rolling-resistance power released within reach of the interface during a
/// contact time `t_s`: min(1, sqrt(a_tread t) / tread depth) (heat generated uniformly through
/// the tread depth; only the layer within the thermal penetration depth conducts to the surface
/// while in contact).
pub(crate) fn rolling_heat_share(compound: &Compound, tread_depth_m: f64, t_s: f64) -> f64 {
    ((compound.solid.diffusivity_m2_s() * t_s.max(0.0)).sqrt() / tread_depth_m.max(1e-4)).min(1.0)
}

/// Longitudinal slip stiffness over load, dF_x/dkappa / F_z, at kappa -> 0 (the slope of the
/// drawbar curve at 0.001 % slip, where the whole patch adheres) at travel speed `speed_mps`.
pub fn slip_stiffness_per_fz(grid: &PressureGrid, pp: &PatchParams, speed_mps: f64, ice_temp_c: f64) -> f64 {
    let k = 1e-5;
    let mut pp = *pp;
    pp.rolling_resistance = 0.0;
    let kin = Kinematics { travel_speed_mps: speed_mps, slip_ratio: k, slip_angle_rad: 0.0, ice_temp_c };
    solve_patch_at(grid, &kin, &pp).summary.drawbar_coeff / k
}
