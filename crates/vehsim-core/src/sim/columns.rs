//! A recorded row as a flat list of numbers: the column names (units in the names) and the values
//! in that order. `timeseries.csv`, the step API's observation and the Python bindings use both.

use super::observer::Row;

/// Column names of timeseries.csv, units in the names.
pub const COLUMNS: &[&str] = &[
    "t_s",
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "sideslip_rad",
    "ax_mps2",
    "ay_mps2",
    "steer_rad",
    "alpha_front_rad",
    "alpha_rear_rad",
    "kappa_front",
    "kappa_rear",
    "fx_front_n",
    "fy_front_n",
    "fx_rear_n",
    "fy_rear_n",
    "omega_front_radps",
    "omega_rear_radps",
    "drive_torque_nm",
    "brake_torque_nm",
    "speed_target_mps",
    "path_error_m",
    "contact_temp_front_c",
    "contact_temp_rear_c",
    "roll_rad",
    "fz_fl_n",
    "fz_fr_n",
    "fz_rl_n",
    "fz_rr_n",
];

/// One row's values in the order of [`COLUMNS`] (the units are in the names).
pub fn row_values(r: &Row) -> [f64; 32] {
    let o = &r.obs;
    let k = &o.kin;
    [
        r.t_s,
        k.x_m,
        k.y_m,
        k.yaw_rad,
        k.vx_mps,
        k.vy_mps,
        k.yaw_rate_radps,
        k.sideslip_rad(),
        o.ax_mps2,
        o.ay_mps2,
        r.inputs.steer_rad,
        o.alpha_rad[0],
        o.alpha_rad[1],
        o.kappa[0],
        o.kappa[1],
        o.fx_n[0],
        o.fy_n[0],
        o.fx_n[1],
        o.fy_n[1],
        o.omega_radps[0],
        o.omega_radps[1],
        r.inputs.drive_torque_nm,
        r.inputs.brake_torque_nm,
        r.speed_target_mps,
        r.path_error_m,
        o.contact_temp_axle_c[0],
        o.contact_temp_axle_c[1],
        o.roll_rad,
        o.fz_n[0],
        o.fz_n[1],
        o.fz_n[2],
        o.fz_n[3],
    ]
}
