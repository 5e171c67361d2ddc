//! Tests of the Shepp–Logan phantom: region values, symmetry, range, partial-volume edges and
//! noise.

use super::*;

/// The voxel nearest to a point given in table coordinates (y anterior), at grid size `n`.
fn voxel_at(table: [f64; 3], n: u32) -> [u32; 3] {
    let world = [table[0], -table[1], table[2]];
    world.map(|u| (((u + 1.0) * n as f64 / 2.0 - 0.5).round() as u32).min(n - 1))
}

/// Points well inside each region (table coordinates) and the HU the module documents.
const PROBES: [(&str, [f64; 3], f64); 12] = [
    ("air", [0.95, 0.95, 0.95], AIR_HU),
    ("skull at the forehead", [0.0, 0.888, 0.0], BONE_HU),
    ("skull at the vertex", [0.0, 0.0, 0.795], BONE_HU),
    ("brain", [0.4, -0.3, 0.3], BRAIN_HU),
    ("right ventricle", [0.22, 0.0, 0.0], CSF_HU),
    ("left ventricle", [-0.22, 0.0, 0.0], CSF_HU),
    ("central mass", [0.0, 0.35, -0.15], 45.0),
    ("anterior lesion", [0.0, 0.1, 0.25], 60.0),
    ("posterior lesion", [0.0, -0.1, 0.25], 60.0),
    ("feature 8", [-0.08, -0.605, 0.0], 80.0),
    ("feature 9", [0.0, -0.606, 0.0], 50.0),
    ("feature 10", [0.06, -0.605, 0.0], 15.0),
];

#[test]
fn regions_have_their_hounsfield_values() {
    // At n = 128 (1.8 mm voxels) the voxel nearest to each probe lies wholly inside its
    // region, even for the 4.6 mm features 9 and 10, so without noise only rounding (0.5 HU)
    // separates it from the documented value; the noise adds at most NOISE_BOUND_HU.
    let n = 128;
    let clean = generate(n, 0.0).expect("valid size");
    let noisy = shepp_logan(n).expect("valid size");
    for (name, point, expected) in PROBES {
        let [x, y, z] = voxel_at(point, n);
        let v = clean.value(x, y, z);
        if name.starts_with("skull") {
            // The skull at the vertex is 3.45 mm thick (semi-axes 0.81 and 0.78 of 115 mm); its
            // edges are Gaussians of σ = √(1² + 1.8²/12) = 1.13 mm (the PSF and the voxel's box).
            // The nearest voxel centre lies up to 0.9 mm off the slab's middle, where the profile
            // keeps ½(erf(2.63/1.59) + erf(0.83/1.59)) = 76 % of the step: at least 75 %.
            assert!(
                v - AIR_HU >= 0.75 * (BONE_HU - AIR_HU) && v <= BONE_HU + 0.5,
                "{name}: {v} HU, expected nearly {expected}"
            );
            continue;
        }
        // Features 8–10 are 4.6–5.3 mm across in two axes; through edges of σ 1.13 mm, at a
        // voxel centre up to 0.9 mm off theirs, each of those axes keeps
        // ½(erf(3.2/1.6) + erf(1.4/1.6)) = 89 % of the contrast: at most a quarter is lost.
        let blur = if name.starts_with("feature") {
            0.25 * (expected - BRAIN_HU).abs()
        } else {
            0.0
        };
        assert!(
            (v - expected).abs() <= 0.5 + blur,
            "{name}: {v} HU, expected {expected}"
        );
        let v = noisy.value(x, y, z);
        assert!(
            (v - expected).abs() <= NOISE_BOUND_HU + 0.5 + blur,
            "{name} (noisy): {v} HU, expected {expected}"
        );
    }
    assert_eq!(noisy.extent_mm(), [FIELD_OF_VIEW_MM; 3]);
}

#[test]
fn mirror_symmetric_where_the_table_is() {
    // Ellipsoids 3, 4, 8 and 10 differ between the left and right halves; everything else
    // is symmetric under x → −x, and so must the noise-free samples be, exactly.
    let n = 64;
    let v = generate(n, 0.0).expect("valid size");
    let voxel = 2.0 / n as f64;
    let asymmetric: Vec<Prepared> = [2, 3, 7, 9].map(|i| Prepared::new(i, voxel, 0.0)).into();
    let near_asymmetric = |x: u32, y: u32, z: u32| {
        let p = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5) * voxel - 1.0;
        asymmetric.iter().any(|e| {
            let d = (p - e.centre).abs();
            d.cmple(e.half_extent + voxel).all()
        })
    };
    let mut compared = 0;
    for z in 0..n {
        for y in 0..n {
            for x in 0..n / 2 {
                let m = n - 1 - x;
                if near_asymmetric(x, y, z) || near_asymmetric(m, y, z) {
                    continue;
                }
                assert_eq!(v.value(x, y, z), v.value(m, y, z), "at ({x}, {y}, {z})");
                compared += 1;
            }
        }
    }
    // Most of the volume is compared, so the test cannot pass vacuously.
    assert!(compared > n * n * n / 4, "compared only {compared}");
}

#[test]
fn values_stay_in_range_and_air_is_exact() {
    let v = shepp_logan(64).expect("valid size");
    let range = v.value_range().expect("finite");
    assert_eq!(range.min, AIR_HU);
    assert!(
        range.max <= BONE_HU + NOISE_BOUND_HU + 0.5,
        "max {}",
        range.max
    );
    // At n = 64 (3.6 mm voxels, edge σ = √(1² + 3.6²/12) = 1.44 mm) each edge of the 7.4 mm
    // forehead takes ½ erfc(3.7 / (1.44·√2)) = 1.1 % of its step (air to bone outside, bone to
    // brain inside) off the middle.
    let blur = 0.011 * ((BONE_HU - AIR_HU) + (BONE_HU - BRAIN_HU));
    assert!(
        range.max >= BONE_HU - blur - NOISE_BOUND_HU,
        "max {}",
        range.max
    );
    // The head is about 0.69·0.92·0.81·π/6 ≈ 27 % of the box; the rest is exact air.
    let Samples::I16(s) = v.samples().expect("in memory") else {
        panic!("the phantom is stored as i16")
    };
    let air = s.iter().filter(|&&x| x == -1000).count() as f64 / s.len() as f64;
    // (The point-spread function's tail takes a voxel's width off the exact air at n = 64.)
    assert!((0.68..0.76).contains(&air), "air fraction {air}");
}

#[test]
fn edges_are_anti_aliased_not_staircased() {
    let n = 64;
    let v = shepp_logan(n).expect("valid size");
    // Walk out from the centre along ±x, ±y, ±z. A staircased phantom would jump from bone
    // (or brain, where the skull is thinner than a voxel) straight to −1000; here the last
    // voxel before the air is partial (the surface almost never falls exactly on a voxel
    // face), and the skull's peak lies within two voxels of the air: the point-spread
    // function (σ 1 mm against 3.6 mm voxels here) does not blur the edge away.
    let c = n / 2;
    let rays: [(i32, i32, i32); 6] = [
        (1, 0, 0),
        (-1, 0, 0),
        (0, 1, 0),
        (0, -1, 0),
        (0, 0, 1),
        (0, 0, -1),
    ];
    for (dx, dy, dz) in rays {
        let values: Vec<f64> = (0..n as i32 / 2)
            .map(|t| {
                let at = |c: u32, d: i32| (c as i32 + d * t) as u32;
                v.value(at(c, dx), at(c, dy), at(c, dz))
            })
            .collect();
        let Some(air) = values.iter().position(|&x| x < AIR_HU + 20.0) else {
            panic!("ray {dx},{dy},{dz} never reaches air: {values:?}")
        };
        let edge = values[air - 1];
        assert!(
            edge > AIR_HU + 20.0 && edge < BONE_HU - 20.0,
            "ray {dx},{dy},{dz}: {values:?}"
        );
        let peak = (0..air)
            .max_by(|&a, &b| values[a].total_cmp(&values[b]))
            .unwrap_or(0);
        assert!(air - peak <= 2, "ray {dx},{dy},{dz}: {values:?}");
        // Where the skull (3.2 mm) is thinner than a voxel (3.6 mm) its peak is partial too,
        // but still far above any soft tissue (at most 80 HU).
        assert!(
            values[peak] > 200.0,
            "ray {dx},{dy},{dz}: no skull in {values:?}"
        );
    }
    // And over the whole surface: at n = 64 the head's surface is roughly 8000 voxels.
    let mut between = 0;
    v.samples().expect("in memory").for_each_f64(|x| {
        if x > AIR_HU + 50.0 && x < BRAIN_HU - 50.0 {
            between += 1;
        }
    });
    assert!(between > 3000, "only {between} partial-volume voxels");
}

#[test]
fn noise_is_mild_bounded_and_absent_in_air() {
    let n = 64;
    let clean = generate(n, 0.0).expect("valid size");
    let noisy = shepp_logan(n).expect("valid size");
    let (Samples::I16(a), Samples::I16(b)) = (
        clean.samples().expect("in memory"),
        noisy.samples().expect("in memory"),
    ) else {
        panic!("the phantom is stored as i16")
    };
    let (mut n_brain, mut sum, mut sum_sq) = (0u32, 0.0, 0.0);
    for (&c, &x) in a.iter().zip(b) {
        let d = (x - c) as f64;
        if c == -1000 {
            assert_eq!(x, -1000, "noise in air");
        }
        // Two roundings separate the samples from the unrounded noise: 1 HU.
        assert!(d.abs() <= NOISE_BOUND_HU + 1.0);
        if c as f64 == BRAIN_HU {
            n_brain += 1;
            sum += d;
            sum_sq += d * d;
        }
    }
    let sigma = (sum_sq / n_brain as f64 - (sum / n_brain as f64).powi(2)).sqrt();
    // Rounding to integers adds a variance of 1/12; over ~30 000 brain voxels the estimate
    // of σ ≈ √(9 + 1/12) = 3.01 is good to about 1 %; allow 5 %.
    assert!(n_brain > 20_000, "{n_brain} brain voxels");
    assert!((sigma - 3.01).abs() < 0.15, "noise σ {sigma}");
}

#[test]
fn zero_size_is_an_error() {
    assert!(matches!(
        shepp_logan(0),
        Err(VolumeError::ZeroDimension { .. })
    ));
    let v = shepp_logan(1).expect("a single voxel is a valid volume");
    assert_eq!(v.dims(), [1; 3]);
}

#[test]
fn the_error_function_matches_tabulated_values() {
    // erfc at 0, ±0.5, ±1, 2, 3 (Abramowitz & Stegun, Table 7.1).
    for (x, want) in [
        (0.0, 1.0),
        (0.5, 0.479_500_122),
        (-0.5, 1.520_499_878),
        (1.0, 0.157_299_207),
        (-1.0, 1.842_700_793),
        (2.0, 0.004_677_735),
        (3.0, 0.000_022_090),
    ] {
        let got = super::erfc(x);
        assert!(
            (got - want).abs() < 2e-7 * want.max(1e-3) + 1e-9,
            "erfc({x}) = {got}"
        );
    }
}

#[test]
fn surfaces_span_the_point_spread_function_not_one_voxel() {
    // At n = 256 (0.9 mm voxels) the PSF (σ 1 mm) spreads the head's outer surface over
    // 2–3 voxels: along a ray from the centre outwards, the values between 10 % and 90 % of the
    // air-to-bone step take at least two voxels, and the air beyond stays exactly −1000 HU.
    let n = 256;
    let v = generate(n, 0.0).expect("phantom");
    let (y, z) = (n / 2, n / 2);
    let values: Vec<f64> = (0..n).map(|x| v.value(x, y, z)).collect();
    let x_out = (n / 2..n)
        .find(|&x| values[x as usize] <= AIR_HU)
        .expect("air") as usize;
    let step = BONE_HU - AIR_HU;
    let peak = (n as usize / 2..x_out)
        .max_by(|&a, &b| values[a].total_cmp(&values[b]))
        .expect("the skull");
    let between = values[peak..x_out]
        .iter()
        .filter(|&&h| h > AIR_HU + 0.1 * step && h < AIR_HU + 0.9 * step)
        .count();
    assert!(
        between >= 2,
        "edge over {between} voxels: {:?}",
        &values[x_out - 6..x_out]
    );
    assert!(
        between <= 4,
        "edge over {between} voxels: {:?}",
        &values[x_out - 6..x_out]
    );
    assert!(values[x_out..].iter().all(|&h| h == AIR_HU));
}

#[test]
fn the_display_window_shows_every_soft_tissue_region_apart() {
    // The window a scanner would store: each documented soft-tissue value lies inside it, at
    // least 5 HU (1/18 of the width) from either end, so none is clipped to black or white.
    let phantom = shepp_logan(16).expect("valid size");
    let [lo, hi] = phantom
        .provenance()
        .window
        .expect("the phantom has a window");
    assert_eq!([lo, hi], DISPLAY_WINDOW_HU);
    for (name, _, hu) in PROBES
        .iter()
        .filter(|(n, ..)| *n != "air" && !n.starts_with("skull"))
    {
        assert!(
            hu - lo >= 5.0 && hi - hu >= 5.0,
            "{name}: {hu} HU at the window's edge"
        );
    }
}
