//! The `leapview` binary: render and info on real data, and one-line errors with status 2 on bad
//! input.

use crate::common;
use crate::common::leapview;

use std::process::Output;

use leapview::imaging::ImageF32;

fn stderr_lines(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.starts_with("leapview:"))
        .map(String::from)
        .collect()
}

#[test]
fn render_writes_png_and_exr_of_a_real_volume() {
    let data = common::data_dir().join("mra_head_200x256x120_uint8.nrrd");
    let dir = common::TempDir::new("cli-render");
    let png = dir.path().join("mra.png");
    let exr = dir.path().join("mra.exr");
    for out in [&png, &exr] {
        let o = leapview(&[
            "render",
            data.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
            "--tf",
            "mr-angio",
            "--size",
            "96x64",
            "--view",
            "-z",
            "--path",
            "compute",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let a = ImageF32::read_png(&png).expect("png");
    assert_eq!((a.width, a.height), (96, 64));
    // Vessels are red: some pixels must be clearly red, most background black.
    let red = a
        .pixels
        .iter()
        .filter(|p| p[0] > 0.3 && p[0] > 2.0 * p[2])
        .count();
    assert!(red > 20, "vessels visible: {red} red pixels");
    let exr_img = image::open(&exr).expect("exr").to_rgba32f();
    assert_eq!(exr_img.dimensions(), (96, 64));
    // The EXR holds the same values as the PNG before quantisation.
    let max_diff = exr_img
        .pixels()
        .zip(&a.pixels)
        .flat_map(|(e, p)| (0..3).map(move |c| (e.0[c] - p[c]).abs()))
        .fold(0.0f32, f32::max);
    assert!(max_diff <= 0.5 / 255.0 + 1e-6, "{max_diff}");
}

#[test]
fn stats_report_samples_and_gpu_time() {
    let data = common::data_dir().join("mra_head_200x256x120_uint8.nrrd");
    let dir = common::TempDir::new("cli-stats");
    let out = dir.path().join("s.png");
    let o = leapview(&[
        "render",
        data.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
        "--size",
        "32x32",
        "--stats",
        "--strategy",
        "rc",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let value = |key: &str| -> u64 {
        let line = text
            .lines()
            .find(|l| l.starts_with(key))
            .unwrap_or_else(|| panic!("no {key} in {text}"));
        line.split_whitespace()
            .nth(1)
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{line}"))
    };
    assert!(value("samples:") > 0);
    assert!(value("visible_samples:") <= value("samples:"));
    assert!(value("rays:") <= 32 * 32);
    assert!(text.contains("gpu_ms:"), "{text}");
}

#[test]
fn info_prints_the_facts() {
    let data = common::data_dir().join("cta_avm_337x319x154_uint8.nrrd");
    let o = leapview(&["info", data.to_str().expect("utf-8"), "--json"]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["dims"], serde_json::json!([337, 319, 154]));
    // data/README.md: 97.6 % of voxels below t = 20.1.
    let air = v["air_fraction"].as_f64().expect("number");
    assert!((air - 0.976).abs() < 0.0006, "{air}");
}

#[test]
fn bad_input_prints_one_line_naming_the_file_and_exits_with_status_2() {
    let dir = common::TempDir::new("cli-bad");
    let empty = dir.write("empty.nrrd", b"");
    let truncated = dir.write(
        "short.nrrd",
        &common::nrrd_file(
            &[
                "type: uint8",
                "dimension: 3",
                "sizes: 8 8 8",
                "encoding: raw",
            ],
            &[0u8; 100],
        ),
    );
    let huge = dir.write(
        "huge.nrrd",
        &common::nrrd_file(
            &[
                "type: uint16",
                "dimension: 3",
                "sizes: 100000 100000 100000",
                "encoding: gzip",
                "endian: little",
            ],
            &common::gzip(&[0u8; 64]),
        ),
    );
    let png = dir.path().join("out.png");
    let out = png.to_str().expect("utf-8");
    let missing = dir.path().join("missing.nii.gz");
    for path in [
        &empty,
        &truncated,
        &huge,
        &missing,
        &dir.path().to_path_buf(),
    ] {
        let p = path.to_str().expect("utf-8");
        for args in [vec!["render", p, "--out", out], vec!["info", p]] {
            let o = leapview(&args);
            assert_eq!(
                o.status.code(),
                Some(2),
                "{args:?}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            let lines = stderr_lines(&o);
            assert_eq!(lines.len(), 1, "{args:?}: {lines:?}");
            assert!(
                lines[0].ends_with(p),
                "{args:?}: the line names the file last: {}",
                lines[0]
            );
        }
    }
    assert!(!png.exists(), "no image for bad input");
    let data = common::data_dir().join("mra_head_200x256x120_uint8.nrrd");
    let o = leapview(&[
        "render",
        data.to_str().expect("utf-8"),
        "--out",
        out,
        "--tf",
        "no-such-preset",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr_lines(&o)[0].contains("no-such-preset"));
}

#[test]
fn every_mode_and_its_parameters_reach_the_renderer() {
    let data = common::data_dir().join("mra_head_200x256x120_uint8.nrrd");
    let data = data.to_str().expect("utf-8");
    let dir = common::TempDir::new("cli-modes");
    let render = |name: &str, extra: &[&str]| {
        let out = dir.path().join(format!("{name}.png"));
        let mut args = vec![
            "render",
            data,
            "--out",
            out.to_str().expect("utf-8"),
            "--size",
            "48x48",
            "--view",
            "-z",
            "--tf",
            "mr-angio",
        ];
        args.extend_from_slice(extra);
        let o = leapview(&args);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        ImageF32::read_png(&out).expect("png")
    };
    let mean = |img: &ImageF32| {
        img.pixels.iter().map(|p| p[0] as f64).sum::<f64>() / img.pixels.len() as f64
    };
    // A narrower MIP window brightens the image: the flag reaches the shader.
    let wide = render("mip-wide", &["--mode", "mip", "--window", "0,255"]);
    let narrow = render("mip-narrow", &["--mode", "mip", "--window", "0,60"]);
    assert!(
        mean(&narrow) > 1.5 * mean(&wide),
        "{} vs {}",
        mean(&narrow),
        mean(&wide)
    );
    // A radiograph whitens as the attenuation per mm rises.
    let thin = render(
        "xray-thin",
        &["--mode", "xray-attenuation", "--xray-density", "0.005"],
    );
    let dense = render(
        "xray-dense",
        &["--mode", "xray-attenuation", "--xray-density", "0.05"],
    );
    assert!(
        mean(&dense) > mean(&thin),
        "radiograph: more attenuation is brighter"
    );
    // An isosurface above the data's maximum shows only the background.
    let none = render(
        "iso-none",
        &["--mode", "iso", "--iso", "300", "--strategy", "rc-s"],
    );
    assert!(none.pixels.iter().all(|p| p[..3] == [0.0; 3]));
    let lit = render(
        "iso-lit",
        &["--mode", "iso", "--iso", "120", "--iso-refine", "8"],
    );
    let unlit = render(
        "iso-unlit",
        &["--mode", "iso", "--iso", "120", "--shading", "off"],
    );
    assert!(
        mean(&lit) > 0.0 && lit.pixels != unlit.pixels,
        "lighting changes the image"
    );
    let side = render(
        "dvr-side",
        &[
            "--light",
            "1,0,0",
            "--phong",
            "0.1,0.9,0.5,40",
            "--gradient",
            "fourth-order",
        ],
    );
    let head = render("dvr-head", &[]);
    assert_ne!(
        side.pixels, head.pixels,
        "the light direction reaches the shader"
    );
    // Quality presets, pre-integration and texel precision reach the renderer: each changes
    // the picture (Fast's one-voxel jittered steps, Reference's ⅛-voxel pre-integrated ones,
    // 8-bit texels are exact for this 8-bit scan so the same picture as auto).
    let balanced = render("quality-balanced", &["--quality", "balanced"]);
    let fast = render("quality-fast", &["--quality", "fast"]);
    let reference = render("quality-reference", &["--quality", "reference"]);
    assert_ne!(fast.pixels, balanced.pixels, "fast = balanced");
    assert_ne!(reference.pixels, balanced.pixels, "reference = balanced");
    let pre = render("preintegrated", &["--preintegrate", "--step", "2"]);
    let post = render("post-classified", &["--step", "2"]);
    assert_ne!(pre.pixels, post.pixels, "--preintegrate changes nothing");
    let cropped = render("cropped", &["--crop", "0:100,0:256,0:120"]);
    assert_ne!(cropped.pixels, head.pixels, "--crop changes nothing");
    let eight = render("texels-8", &["--precision", "unorm8"]);
    assert_eq!(
        eight.pixels, head.pixels,
        "8-bit data in 8-bit texels is exact"
    );
    for bad in [
        &["--quality", "fast", "--step", "2"][..],
        &["--mode", "mip", "--window", "60,0"],
        &["--light", "0,0,0"],
        &["--phong", "1,1,1"],
        &["--iso-refine", "99", "--mode", "iso"],
        &["--block", "12"],
        &["--crop", "0:500,0:10,0:10"],
        &["--crop", "5:5,0:10,0:10"],
    ] {
        let out = dir.path().join("bad.png");
        let mut args = vec!["render", data, "--out", out.to_str().expect("utf-8")];
        args.extend_from_slice(bad);
        let o = leapview(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
    }
}

#[test]
fn anatomical_views_follow_the_orientation() {
    // The shared NRRDs carry no orientation: RAS is assumed, so the view from anterior looks
    // along −y with +z up, exactly the axis view `-y`; from superior it looks down −z with
    // anterior (+y) up, which is `-z` turned by 180°.
    let data = common::data_dir().join("mra_head_200x256x120_uint8.nrrd");
    let data = data.to_str().expect("utf-8");
    let dir = common::TempDir::new("cli-views");
    let render = |view: &str| {
        let out = dir
            .path()
            .join(format!("{}.png", view.replace(['+', '-'], "_")));
        let o = leapview(&[
            "render",
            data,
            "--out",
            out.to_str().expect("utf-8"),
            "--size",
            "40x40",
            "--tf",
            "mr-angio",
            "--projection",
            "orthographic",
            // One path for every view: `auto` times both in each process and may choose
            // differently under load, and the paths' pixels need not be equal.
            "--path",
            "compute",
            "--view",
            view,
        ]);
        (o.status.code(), ImageF32::read_png(&out).ok())
    };
    let (_, anterior) = render("A");
    let (_, minus_y) = render("-y");
    assert_eq!(anterior.expect("A").pixels, minus_y.expect("-y").pixels);
    let (_, superior) = render("superior");
    let (_, minus_z) = render("-z");
    let (s, z) = (superior.expect("S"), minus_z.expect("-z"));
    let w = s.width as usize;
    let h = s.height as usize;
    let turned: Vec<[f32; 4]> = (0..h * w).map(|i| z.pixels[h * w - 1 - i]).collect();
    assert_eq!(s.pixels, turned, "S is -z turned by 180°");
    let (code, _) = render("Q");
    assert_eq!(code, Some(2), "an unknown view is bad input");
}

#[test]
fn a_mirrored_file_renders_as_the_patient_not_their_mirror_image() {
    // One patient (a dim body with a bright ball on their left, a smaller one in front) stored
    // twice: RAS (i to the right), and LAS (i to the left, samples reversed along i), which is a
    // mirror image of the patient in the index frame. Both must render the same from every side,
    // and from the front the patient's left is on the viewer's right.
    const DIMS: [u32; 3] = [12, 10, 8];
    let [nx, ny, nz] = DIMS.map(|d| d as usize);
    let mut ras = vec![20u8; nx * ny * nz];
    for (i, v) in ras.iter_mut().enumerate() {
        let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
        let dist = |c: [f64; 3]| {
            let d = [x as f64 - c[0], y as f64 - c[1], z as f64 - c[2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        };
        if dist([2.0, 5.0, 4.0]) < 2.0 {
            *v = 250; // the patient's left: low i in RAS
        } else if dist([6.0, 8.0, 4.0]) < 1.5 {
            *v = 150; // anterior: high j
        }
    }
    let las: Vec<u8> = ras
        .chunks(nx)
        .flat_map(|row| row.iter().rev().copied())
        .collect();
    let dir = common::TempDir::new("cli-mirrored");
    let file = |name: &str, srow_x: [f32; 4], data: &[u8]| {
        let mut spec = common::NiftiSpec::new(leapview::volume::ScalarType::U8, DIMS, [1.0; 3]);
        spec.sform = Some([srow_x, [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]);
        dir.write(name, &spec.file(data))
    };
    let ras_path = file("ras.nii", [1.0, 0.0, 0.0, 0.0], &ras);
    let las_path = file("las.nii", [-1.0, 0.0, 0.0, 11.0], &las);

    let o = leapview(&["info", las_path.to_str().expect("utf-8"), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(info["orientation_in_file"], "LAS");
    assert_eq!(info["orientation"], "RAS");
    assert_eq!(info["reversed_i"], true);

    let render = |path: &std::path::Path, view: &str| {
        let out = dir.path().join(format!(
            "{}-{view}.png",
            path.file_stem().and_then(|s| s.to_str()).expect("name")
        ));
        let o = leapview(&[
            "render",
            path.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
            "--size",
            "48x48",
            "--mode",
            "mip",
            "--projection",
            "orthographic",
            // One path for both files (`auto` may choose differently in each process).
            "--path",
            "compute",
            "--view",
            view,
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        ImageF32::read_png(&out).expect("png")
    };
    for view in ["A", "P", "L", "R", "S", "I"] {
        let (a, b) = (render(&ras_path, view), render(&las_path, view));
        assert_eq!(
            a.pixels, b.pixels,
            "view from {view}: RAS and LAS files differ"
        );
    }
    // From the front, superior up: the bright ball (the patient's left) is right of centre.
    let front = render(&ras_path, "A");
    let w = front.width as usize;
    let (mut left, mut right) = (0.0f32, 0.0f32);
    for (i, p) in front.pixels.iter().enumerate() {
        if p[0] > 0.9 {
            if i % w < w / 2 {
                left += 1.0
            } else {
                right += 1.0
            }
        }
    }
    assert!(
        right > 0.0 && left == 0.0,
        "bright pixels: {left} left, {right} right"
    );
}

#[test]
fn orientation_given_on_the_command_line_puts_the_head_up() {
    // A file without orientation whose slices run from the top of the head down (as the shared
    // CT head's): the bright "skull cap" is at k = 1, the dim body below it. RAS is assumed, so
    // from the front the cap shows at the bottom; `--orientation RAI` says k points inferior and
    // puts it on top.
    const DIMS: [u32; 3] = [10, 10, 12];
    let [nx, ny, nz] = DIMS.map(|d| d as usize);
    let samples: Vec<u8> = (0..nx * ny * nz)
        .map(|i| if i / (nx * ny) <= 2 { 250 } else { 40 })
        .collect();
    let dir = common::TempDir::new("cli-orientation");
    let mut lines = common::nrrd_lines(leapview::volume::ScalarType::U8, DIMS, "raw", false);
    lines.push("spacings: 1 1 1".into());
    let refs: Vec<&str> = lines.iter().map(String::as_str).collect();
    let path = dir.write("head.nrrd", &common::nrrd_file(&refs, &samples));
    let path = path.to_str().expect("utf-8");

    let info = |extra: &[&str]| {
        let mut args = vec!["info", path, "--json"];
        args.extend_from_slice(extra);
        let o = leapview(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).expect("json")
    };
    let plain = info(&[]);
    assert_eq!(plain["orientation"], serde_json::Value::Null);
    let given = info(&["--orientation", "rai"]);
    // RAI is a mirror image of RAS: read reversed along i, shown as LAI.
    assert_eq!(given["orientation_in_file"], "RAI");
    assert_eq!(given["orientation"], "LAI");
    assert_eq!(given["orientation_source"], "user");
    assert_eq!(given["orientation_in_header"], serde_json::Value::Null);
    let text = leapview(&["info", path, "--orientation", "RAI"]);
    let text = String::from_utf8_lossy(&text.stdout).into_owned();
    assert!(
        text.contains("RAI as given with --orientation (the header has none)"),
        "{text}"
    );

    // Where the cap shows from the front: the share of its bright pixels in the top half.
    let cap_on_top = |extra: &[&str]| {
        let out = dir.path().join(format!("front{}.png", extra.len()));
        let mut args = vec![
            "render",
            path,
            "--out",
            out.to_str().expect("utf-8"),
            "--size",
            "40x40",
            "--mode",
            "mip",
            "--projection",
            "orthographic",
            "--view",
            "A",
        ];
        args.extend_from_slice(extra);
        let o = leapview(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let image = ImageF32::read_png(&out).expect("png");
        let w = image.width as usize;
        let bright: Vec<usize> = (0..image.pixels.len())
            .filter(|&i| image.pixels[i][0] > 0.9)
            .map(|i| i / w)
            .collect();
        assert!(!bright.is_empty(), "the cap shows");
        let top = bright
            .iter()
            .filter(|&&row| row < image.height as usize / 2);
        top.count() as f64 / bright.len() as f64
    };
    assert_eq!(cap_on_top(&[]), 0.0, "RAS assumed: the cap at the bottom");
    assert_eq!(cap_on_top(&["--orientation", "RAI"]), 1.0, "RAI: on top");

    let bad = leapview(&["info", path, "--orientation", "RAX"]);
    assert_eq!(bad.status.code(), Some(2));
    let lines = stderr_lines(&bad);
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(
        lines[0].contains("one each of R/L, A/P and S/I"),
        "{lines:?}"
    );
}

/// `leapview shaders` prints the driver's statistics of each compute and fragment variant where
/// the driver reports them (VK_KHR_pipeline_executable_properties); where none does (lavapipe of
/// Mesa 22.3) it says so in one line with status 1, naming the devices there are; a device name
/// that matches none, or `auto` as a path, is bad input (status 2). Never a crash.
#[test]
fn shaders_prints_the_drivers_statistics_or_says_why_not() {
    let o = leapview(&["shaders", "--modes", "dvr,mip", "--sizes", "512x512"]);
    if o.status.success() {
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            text.contains("| mode | strategy | path | size | split |"),
            "{text}"
        );
        // Per path, DVR: RC-t, RC-s, RC-s-df; MIP: RC-t and RC-s (its variant for rc-s-df
        // too); the fragment path's graphics pipelines have a vertex and a fragment executable.
        let rows = |path: &str| {
            text.lines()
                .filter(|l| l.starts_with("| dvr |") || l.starts_with("| mip |"))
                .filter(|l| l.contains(&format!("| {path} |")))
                .count()
        };
        assert!(rows("compute") >= 5 && rows("fragment") >= 5, "{text}");
    } else {
        assert_eq!(o.status.code(), Some(1), "{}", common::stderr(&o));
        let lines = stderr_lines(&o);
        assert_eq!(lines.len(), 1, "{}", common::stderr(&o));
        assert!(lines[0].contains("pipeline statistics"), "{}", lines[0]);
        assert!(lines[0].contains("devices: "), "{}", lines[0]);
    }
    let o = leapview(&["shaders", "--paths", "auto"]);
    assert_eq!(o.status.code(), Some(2), "{}", common::stderr(&o));
    assert!(
        common::stderr(&o).contains("--paths takes compute and fragment"),
        "{}",
        common::stderr(&o)
    );
    let o = leapview(&["shaders", "--device", "no such gpu"]);
    assert_eq!(o.status.code(), Some(2), "{}", common::stderr(&o));
    let lines = stderr_lines(&o);
    assert!(
        lines.len() == 1 && lines[0].contains("\"no such gpu\""),
        "{}",
        common::stderr(&o)
    );
}

/// A 2D colour image without any patient orientation (pydicom's `SC_rgb_rle.dcm`, 100 x 100,
/// RLE): `render` writes the image itself, as stored (row 0 at the top, column 0 at the left) and
/// in its own colours, and says so; pydicom's pixels are the reference.
#[test]
fn render_writes_a_2d_colour_image_as_stored_in_its_colours() {
    let dir = common::TempDir::new("cli-render-2d");
    let reference = dir.path().join("rgb.raw");
    let script = format!(
        "import pydicom, pydicom.data\n\
         ds = pydicom.dcmread(pydicom.data.get_testdata_file('SC_rgb_rle.dcm'))\n\
         open({:?}, 'wb').write(ds.pixel_array.astype('uint8').tobytes())\n\
         print(pydicom.data.get_testdata_file('SC_rgb_rle.dcm'))",
        reference.display().to_string()
    );
    let out = std::process::Command::new(common::python())
        .args(["-c", &script])
        .output()
        .expect("python");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let file = String::from_utf8_lossy(&out.stdout).trim().to_string();
    let png = dir.path().join("rgb.png");
    let o = leapview(&[
        "render",
        &file,
        "--out",
        png.to_str().expect("utf-8"),
        "--size",
        "100x100",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let note = String::from_utf8_lossy(&o.stderr);
    assert!(
        note.contains("2D image (100 x 100)") && note.contains("own colours"),
        "{note}"
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("edges: as stored"), "{stdout}");
    let image = image::open(&png).expect("png").to_rgb8();
    let expected = std::fs::read(&reference).expect("pydicom's pixels");
    assert_eq!(image.dimensions(), (100, 100));
    let worst = image
        .as_raw()
        .iter()
        .zip(&expected)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap_or(0);
    // Pixel centres fall on voxel centres: the texture unit returns each voxel's own 8-bit colour.
    assert!(
        worst <= 1,
        "largest difference from pydicom's pixels: {worst} levels"
    );
}

/// `-h` and `--help` of the program and of every command: `-h` fits a terminal screen, neither
/// shows Rust code paths or intra-doc links, and the top level names every file format.
mod help {
    use crate::common::leapview;

    /// The most lines `-h` may print: a terminal screen.
    const SCREEN_LINES: usize = 50;

    /// Runs `leapview ARGS` and returns what it printed, which must be help.
    fn help_text(args: &[&str]) -> String {
        let o = leapview(args);
        assert!(
            o.status.success(),
            "leapview {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8(o.stdout).expect("help is UTF-8")
    }

    /// The commands the top-level help lists under "Commands:" (without `help` itself).
    fn commands() -> Vec<String> {
        let text = help_text(&["-h"]);
        let commands: Vec<String> = text
            .lines()
            .skip_while(|l| *l != "Commands:")
            .skip(1)
            .take_while(|l| !l.trim().is_empty())
            .filter_map(|l| l.split_whitespace().next())
            .filter(|c| *c != "help")
            .map(String::from)
            .collect();
        for expected in [
            "render", "info", "bench", "accuracy", "generate", "convert", "slice", "shaders",
        ] {
            assert!(
                commands.iter().any(|c| c == expected),
                "{expected} missing from {commands:?}"
            );
        }
        commands
    }

    /// Fails if `text` (the help of `what`) shows a Rust path, an intra-doc link or Markdown code.
    fn assert_no_code(what: &str, text: &str) {
        for bad in ["::", "[`", "`"] {
            let line = text.lines().find(|l| l.contains(bad));
            assert!(
                line.is_none(),
                "{what} shows {bad:?}: {}",
                line.unwrap_or("")
            );
        }
    }

    #[test]
    fn short_help_fits_a_screen_and_no_help_shows_code_paths() {
        let mut invocations = vec![vec![]];
        invocations.extend(commands().into_iter().map(|c| vec![c]));
        for words in invocations {
            let mut short: Vec<&str> = words.iter().map(String::as_str).collect();
            let mut long = short.clone();
            short.push("-h");
            long.push("--help");
            let what = format!("leapview {}", short.join(" "));
            let text = help_text(&short);
            let lines = text.lines().count();
            assert!(
                lines <= SCREEN_LINES,
                "{what} prints {lines} lines, more than {SCREEN_LINES}:\n{text}"
            );
            assert_no_code(&what, &text);
            let what = format!("leapview {}", long.join(" "));
            let long_text = help_text(&long);
            assert_no_code(&what, &long_text);
            assert!(
                long_text.lines().count() >= lines,
                "{what} is shorter than -h"
            );
        }
    }

    #[test]
    fn top_level_help_names_every_format() {
        for flag in ["-h", "--help"] {
            let text = help_text(&[flag]);
            for format in [
                "NRRD",
                ".nhdr",
                "NIfTI",
                ".nii.gz",
                "DICOM",
                "MetaImage",
                ".mha",
                "OME-Zarr",
                "TIFF",
                "raw",
            ] {
                assert!(
                    text.contains(format),
                    "leapview {flag} does not name {format}:\n{text}"
                );
            }
        }
    }
}
