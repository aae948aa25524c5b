//! Bad input to the ATIIM pressure sources and scenario files: clear `Error::Input` messages.

use std::path::{Path, PathBuf};

use vehsim_core::Error;
use vehsim_spec::contact::ScenarioSpec;
use vehsim_spec::patch_file::{parse_csv, read_png_map, ImageLayout};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/atiim").join(name)
}

fn input_message(e: Error) -> String {
    match e {
        Error::Input { .. } => e.to_string(),
        other => panic!("expected Error::Input, got {other:?}"),
    }
}

#[test]
fn negative_pressure_names_file_row_and_column() {
    let f = data("negative.csv");
    let text = std::fs::read_to_string(&f).unwrap();
    let msg = input_message(parse_csv(&f, &text, 0.005, 0.005).unwrap_err());
    assert!(msg.contains("negative.csv") && msg.contains("row 2") && msg.contains("column 2"), "{msg}");
    assert!(msg.contains("negative"), "{msg}");
}

#[test]
fn wrong_grid_shape_is_rejected() {
    let f = data("ragged.csv");
    let text = std::fs::read_to_string(&f).unwrap();
    let msg = input_message(parse_csv(&f, &text, 0.005, 0.005).unwrap_err());
    assert!(msg.contains("ragged.csv") && msg.contains("row 2") && msg.contains("3 columns"), "{msg}");
    let msg = input_message(parse_csv(&f, "# only a comment\n", 0.005, 0.005).unwrap_err());
    assert!(msg.contains("empty"), "{msg}");
    let msg = input_message(parse_csv(&f, "1,2\nx,3\n", 0.005, 0.005).unwrap_err());
    assert!(msg.contains("row 2") && msg.contains("'x'"), "{msg}");
}

/// Write an RGB PNG: a footprint of `fp` (w x h) colours and, to its right, an optional bar.
fn png(width: u32, height: u32, px: &dyn Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().unwrap();
        let mut data = Vec::new();
        for y in 0..height {
            for x in 0..width {
                data.extend_from_slice(&px(x, y));
            }
        }
        w.write_image_data(&data).unwrap();
    }
    out
}

/// Colour of bar fraction t in [0, 1] (blue -> red through green), distinct for 64 levels.
fn bar_colour(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    [(255.0 * t) as u8, (255.0 * (1.0 - (2.0 * t - 1.0).abs())) as u8, (255.0 * (1.0 - t)) as u8]
}

fn layout() -> ImageLayout {
    ImageLayout {
        footprint: [0, 0, 10, 8],
        colour_bar: [20, 0, 24, 64],
        bar_min_pa: 0.0,
        bar_max_pa: 630e3,
        tolerance: 40.0,
        dx_m: 0.005,
        dy_m: 0.005,
    }
}

#[test]
fn png_pressure_map_is_decoded_through_its_colour_bar() {
    // bar: 64 rows, top = max. Footprint pixel (x, y) carries level (x + 3 y) of 63 -> p = level * 10 kPa.
    let img = png(24, 64, &|x, y| {
        if x >= 20 {
            bar_colour((63 - y) as f64 / 63.0)
        } else if x < 10 && y < 8 {
            bar_colour((x + 3 * y) as f64 / 63.0)
        } else {
            [255, 255, 255]
        }
    });
    let g = read_png_map(Path::new("map.png"), &img, &layout()).unwrap();
    assert_eq!((g.rows, g.cols), (8, 10));
    for y in 0..8 {
        for x in 0..10 {
            let want = (x + 3 * y) as f64 * 10e3;
            assert!((g.p(y, x) - want).abs() < 1e-6, "({x},{y}): {} vs {want}", g.p(y, x));
        }
    }
}

#[test]
fn png_without_readable_colour_bar_is_rejected() {
    // the bar box is a single grey: no gradient
    let img = png(24, 64, &|x, y| if x >= 20 { [128, 128, 128] } else { bar_colour((x + y) as f64 / 80.0) });
    let msg = input_message(read_png_map(Path::new("map.png"), &img, &layout()).unwrap_err());
    assert!(msg.contains("map.png") && msg.contains("colour bar") && msg.contains("distinct colours"), "{msg}");
    // the bar box lies outside the image
    let mut lay = layout();
    lay.colour_bar = [20, 0, 30, 64];
    let msg = input_message(read_png_map(Path::new("map.png"), &img, &lay).unwrap_err());
    assert!(msg.contains("colour bar") && msg.contains("inside"), "{msg}");
    // not a PNG at all
    let msg = input_message(read_png_map(Path::new("map.png"), b"GIF89a....", &layout()).unwrap_err());
    assert!(msg.contains("PNG"), "{msg}");
}

#[test]
fn scenario_errors_name_the_key() {
    let dir = std::env::temp_dir().join(format!("vehsim-atiim-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        ("name = \"x\"\nbogus = 1\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n", "bogus"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n", "pressure.load_n"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = 5.0\n", "operating.ice_temp_c"),
        ("name = \"x\"\n[pressure]\nsource = \"jpeg\"\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n", "pressure.source"),
        ("name = \"x/../y\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n", "name"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\nshore_a = 120.0\n", "tyre.shore_a"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\nadhesion_peak = 3.0\n", "tyre.adhesion_peak"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\npeak_speed_mps = 0.0\n", "tyre.peak_speed_mps"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\npeak_width = 9.0\n", "tyre.peak_width"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\npressure_exponent = -0.1\n", "tyre.pressure_exponent"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\ntemp_coeff_per_k = 0.5\n", "tyre.temp_coeff_per_k"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\ncarcass_stiffness_kn_per_m = 10.0\n", "tyre.carcass_stiffness_kn_per_m"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\nrolling_resistance = 0.2\n", "tyre.rolling_resistance"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[drawbar]\nslips = [0.1, -1.5]\n", "drawbar.slips[1]"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\ngrid = [1, 1]\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n", "pressure.grid[0]"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\nspeed_exponent = 2.0\n", "tyre.speed_exponent"),
        ("name = \"x\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n[tyre]\nspeed_scale_mps = 0.0\n", "tyre.speed_scale_mps"),
        ("name = \"x\"\n[pressure]\nsource = \"csv\"\nfile = \"missing.csv\"\npixel_length_m = 0.01\npixel_width_m = 0.01\n[operating]\nspeed_mps = 1.0\nslip_ratio = 0.1\nice_temp_c = -3.0\n", "missing.csv"),
    ];
    for (i, (text, key)) in cases.iter().enumerate() {
        let f = dir.join(format!("case{i}.toml"));
        std::fs::write(&f, text).unwrap();
        let msg = input_message(ScenarioSpec::load(&f).unwrap_err());
        assert!(msg.contains(key), "case {i}: '{msg}' should name {key}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
