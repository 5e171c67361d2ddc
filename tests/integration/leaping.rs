//! RC-s: the GPU's min/max pyramid, emptiness table, node flags and distance field equal their
//! CPU references, and leaping changes no image while taking fewer samples.

use crate::common;

use leapview::accel::distance::{FULL_SHIFT, MAX_DISTANCE, sides, two_sided};
use leapview::accel::emptiness::{OpacityIndex, TABLE_SIZE, table_says_empty};
use leapview::accel::pyramid::{MinMax, build_cpu, normalized_values};
use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::counters::FrameCounters;
use leapview::render::VolumeRenderer;
use leapview::render::readback::read_buffer;
use leapview::settings::{IsoSettings, Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace, lut};
use leapview::volume::{Samples, ValueMapping, Volume, synthetic};

fn read_u32(r: &VolumeRenderer, buffer: &wgpu::Buffer, count: u32) -> Vec<u32> {
    let bytes = read_buffer(r.context(), buffer, count as u64 * 4).expect("read");
    bytemuck::cast_slice(&bytes).to_vec()
}

fn render(
    r: &mut VolumeRenderer,
    camera: &Camera,
    settings: RenderSettings,
) -> (leapview::imaging::ImageF32, FrameCounters) {
    common::render_counted(r, camera, settings, [64, 64])
}

/// A 37×50×13 float volume (odd sizes on every axis) with smooth structure and a NaN voxel.
fn odd_volume() -> Volume {
    let dims = [37u32, 50, 13];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let r2 = (x as f32 - 20.0).powi(2)
                    + (y as f32 - 30.0).powi(2)
                    + (z as f32 * 3.0 - 18.0).powi(2);
                v.push(1000.0 * (-r2 / 120.0).exp());
            }
        }
    }
    v[3 + 37 * (4 + 50 * 5)] = f32::NAN;
    Volume::new(
        "odd",
        dims,
        [1.0, 0.8, 2.5],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

fn threshold_tf(from: f64) -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, 0.0], [from, 0.0], [from + 50.0, 0.4], [1000.0, 0.9]],
        color: vec![[0.0, 1.0, 0.5, 0.2], [1000.0, 1.0, 1.0, 1.0]],
        space: ValueSpace::Data,
    }
}

#[test]
fn gpu_structures_equal_the_cpu_references() {
    let volume = odd_volume();
    let tf = threshold_tf(300.0);
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    // Settings left at their default render with the path `auto`.
    common::choose_auto_path(&mut r);
    r.set_transfer_function(&tf);
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    for block in [4u32, 8, 16] {
        let settings = RenderSettings {
            strategy: Strategy::RcSDistance,
            block_vox: Some(block),
            ..RenderSettings::default()
        };
        render(&mut r, &camera, settings);
        let leap = r.leap_structures().expect("built");
        let p = &leap.pyramid;
        let n = p.node_count();
        // Min/max: the GPU decodes texels in f32 (R32Float holds the normalised value), the CPU
        // normalises in f64 then rounds: equal to a few ulps.
        let gpu_minmax: Vec<[f32; 2]> = bytemuck::cast_slice(
            &read_buffer(r.context(), &leap.minmax, n as u64 * 8).expect("read"),
        )
        .to_vec();
        let cpu_minmax = build_cpu(p, &normalized_values(&volume));
        for (i, (g, c)) in gpu_minmax.iter().zip(&cpu_minmax).enumerate() {
            assert!(
                (g[0] - c.min).abs() <= 1e-6 && (g[1] - c.max).abs() <= 1e-6,
                "node {i}: gpu {g:?} cpu {c:?}"
            );
        }
        // Table and flags: exact, from the same baked table and the GPU's own min/max.
        let index = OpacityIndex::from_lut(&lut::bake(
            &tf,
            volume.normalization_range(),
            RenderSettings::default().step_vox,
        ));
        let table = index.table();
        let gpu_table = read_u32(&r, &leap.table, (TABLE_SIZE * TABLE_SIZE) as u32);
        assert!(
            gpu_table.iter().zip(&table).all(|(g, c)| *g == *c as u32),
            "emptiness table differs"
        );
        let flags = read_u32(&r, &leap.node_empty, n);
        for (i, g) in gpu_minmax.iter().enumerate() {
            let expected = table_says_empty(
                &table,
                MinMax {
                    min: g[0],
                    max: g[1],
                },
            );
            assert_eq!(flags[i] == 1, expected, "node {i}");
        }
        assert!(
            flags.contains(&0) && flags.contains(&1),
            "a useful test has both kinds of nodes"
        );
        // Distance field over the leaf level, from the GPU's flags.
        let leaf = p.levels[p.level_of_block(block).expect("level")];
        let empty: Vec<bool> = flags[leaf.offset as usize..(leaf.offset + leaf.count()) as usize]
            .iter()
            .map(|&f| f == 1)
            .collect();
        let gpu_distance = read_u32(&r, &leap.distance[0], leaf.count());
        assert_eq!(gpu_distance, two_sided(leaf.nodes, &empty), "block {block}");

        // Isosurfaces: per-node side bits from the GPU's min/max and the iso value, and the
        // per-side field over the leaf level.
        let iso = RenderSettings {
            mode: Mode::Iso,
            iso: IsoSettings {
                value: Some(200.0),
                ..IsoSettings::default()
            },
            ..settings
        };
        render(&mut r, &camera, iso);
        let leap = r.leap_structures().expect("built");
        let threshold = iso.iso.threshold(volume.normalization_range()) as f32;
        let bits = read_u32(&r, &leap.node_empty, n);
        for (i, g) in gpu_minmax.iter().enumerate() {
            let expected = if g[0] > g[1] {
                3
            } else {
                u32::from(g[1] < threshold) | (u32::from(g[0] >= threshold) << 1)
            };
            assert_eq!(bits[i], expected, "iso node {i}: {g:?} against {threshold}");
        }
        let leaf_bits = &bits[leaf.offset as usize..(leaf.offset + leaf.count()) as usize];
        let below: Vec<bool> = leaf_bits.iter().map(|b| b & 1 != 0).collect();
        let above: Vec<bool> = leaf_bits.iter().map(|b| b & 2 != 0).collect();
        assert!(
            below.contains(&true) && below.contains(&false),
            "block {block}"
        );
        // (Only small blocks fit wholly inside the blob.)
        assert!(block > 4 || above.contains(&true), "block {block}");
        let gpu_sides = read_u32(&r, &leap.distance[0], leaf.count());
        assert_eq!(
            gpu_sides,
            sides(leaf.nodes, &below, &above),
            "iso, block {block}"
        );
    }
}

/// A 2048 × 160 × 12 volume of long runs: a rod along x, a slab across y, a ball and a NaN voxel
/// in empty space, and nothing past x = 1300, so that its rows of leaf blocks hold runs of both
/// kinds longer than the field's cap, and are longer than a subgroup; along x, 512 blocks of 4,
/// longer than the tiled pass takes (the windowed pass), 256 of 8 (the tiled pass).
/// (2048 texels is WebGPU's least 3D-texture limit: every adapter holds it.)
fn long_rows_volume() -> Volume {
    let dims = [2048u32, 160, 12];
    let mut v = vec![0.0f32; (dims[0] * dims[1] * dims[2]) as usize];
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let rod = (100..1300).contains(&x) && (20..26).contains(&y) && (3..7).contains(&z);
                let slab = (1200..1230).contains(&x) && y >= 40;
                let ball = (x as f32 - 600.0).powi(2) + (y as f32 - 120.0).powi(2) < 400.0;
                if rod || slab || ball {
                    v[(x + dims[0] * (y + dims[1] * z)) as usize] = 1000.0;
                }
            }
        }
    }
    v[(40 + dims[0] * (130 + 160 * 9)) as usize] = f32::NAN;
    Volume::new(
        "long rows",
        dims,
        [1.0, 1.0, 1.0],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

/// The distance field's passes (build/distance.wgsl) on long rows: the tiled pass on rows longer
/// than a subgroup with runs longer than the cap, and the windowed pass on rows past the tile,
/// equal the CPU references, from the emptiness flags and from the isosurface's sides.
#[test]
fn the_distance_field_equals_the_cpu_reference_on_long_rows() {
    let volume = long_rows_volume();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    common::choose_auto_path(&mut r);
    r.set_transfer_function(&threshold_tf(300.0));
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    for block in [4u32, 8] {
        let settings = RenderSettings {
            strategy: Strategy::RcSDistance,
            block_vox: Some(block),
            ..RenderSettings::default()
        };
        for mode in [Mode::Dvr, Mode::Iso] {
            let settings = RenderSettings {
                mode,
                iso: IsoSettings {
                    value: Some(500.0),
                    ..IsoSettings::default()
                },
                ..settings
            };
            render(&mut r, &camera, settings);
            let leap = r.leap_structures().expect("built");
            let p = &leap.pyramid;
            let leaf = p.levels[p.level_of_block(block).expect("level")];
            let flags = read_u32(&r, &leap.node_empty, p.node_count());
            let leaf_flags = &flags[leaf.offset as usize..(leaf.offset + leaf.count()) as usize];
            let expected = match mode {
                Mode::Iso => {
                    let below: Vec<bool> = leaf_flags.iter().map(|b| b & 1 != 0).collect();
                    let above: Vec<bool> = leaf_flags.iter().map(|b| b & 2 != 0).collect();
                    sides(leaf.nodes, &below, &above)
                }
                _ => {
                    let empty: Vec<bool> = leaf_flags.iter().map(|&f| f == 1).collect();
                    two_sided(leaf.nodes, &empty)
                }
            };
            let field = read_u32(&r, &leap.distance[0], leaf.count());
            // The test means something: on the side of the empty space (low bits: to the
            // nearest block that is not empty, or not wholly below the iso value), distances
            // at the cap and between; on the other, blocks away from it (the rod and slab are
            // too thin for more).
            let open: Vec<u32> = expected
                .iter()
                .map(|v| v & ((1 << FULL_SHIFT) - 1))
                .collect();
            let solid: Vec<u32> = expected.iter().map(|v| v >> FULL_SHIFT).collect();
            assert!(open.contains(&MAX_DISTANCE), "{mode:?}, block {block}");
            assert!(open.iter().any(|d| (2..MAX_DISTANCE).contains(d)));
            assert!(solid.iter().any(|&d| d >= 1), "{mode:?}, block {block}");
            assert_eq!(field, expected, "{mode:?}, block {block}");
        }
    }
}

/// RC-s must draw RC-t's image from fewer samples, and must take every sample that can
/// contribute (the visible samples are the same).
fn assert_leaping_exact(
    name: &str,
    volume: &Volume,
    tf: &TransferFunction,
    views: &[ViewPreset],
    block: u32,
) {
    let mut r = common::renderer();
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(tf);
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    for &view in views {
        let (dir, up) = view.direction_and_up();
        let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let base = RenderSettings {
                path,
                block_vox: Some(block),
                ..RenderSettings::default()
            };
            let (rct, rct_counts) = render(
                &mut r,
                &camera,
                RenderSettings {
                    strategy: Strategy::RcT,
                    ..base
                },
            );
            for strategy in [Strategy::RcS, Strategy::RcSDistance] {
                let (rcs, rcs_counts) =
                    render(&mut r, &camera, RenderSettings { strategy, ..base });
                // Leapt samples have exactly zero opacity: the images agree to the bit; the issue
                // allows 1/255.
                let label = format!("{name}-{view:?}-{path:?}-{strategy:?}");
                common::assert_close(&label, &rcs, &rct, 1.0 / 255.0, 0.0);
                assert_eq!(
                    rcs_counts.visible_samples, rct_counts.visible_samples,
                    "{label}: every contributing sample taken"
                );
                assert!(
                    rcs_counts.samples <= rct_counts.samples,
                    "{label}: {rcs_counts:?} vs {rct_counts:?}"
                );
                // Leaping only skips grid samples and stops where RC-t stops: what it took and
                // what it skipped add up to RC-t's samples exactly.
                assert_eq!(
                    rcs_counts.samples + rcs_counts.leapt_samples,
                    rct_counts.samples,
                    "{label}: samples taken + leapt ≠ RC-t's"
                );
                assert_eq!(rct_counts.leapt_samples, 0, "{label}: RC-t leapt");
            }
        }
    }
}

#[test]
fn leaping_is_exact_on_synthetic_volumes() {
    let vessels = synthetic::vessel_tree(96, 3).expect("vessels");
    let angio = leapview::transfer::presets::preset("mr-angio").expect("preset");
    assert_leaping_exact(
        "vessels",
        &vessels,
        &angio,
        &[ViewPreset::Oblique, ViewPreset::PlusZ],
        8,
    );
    assert_leaping_exact(
        "odd",
        &odd_volume(),
        &threshold_tf(300.0),
        &[ViewPreset::MinusX, ViewPreset::Oblique],
        4,
    );
}

#[test]
fn leaping_skips_most_samples_of_a_sparse_volume() {
    let volume = synthetic::vessel_tree(96, 3).expect("vessels");
    let tf = leapview::transfer::presets::preset("mr-angio").expect("preset");
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf);
    // Settings left at their default render with the path `auto`.
    common::choose_auto_path(&mut r);
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let (_, rct) = render(
        &mut r,
        &camera,
        RenderSettings {
            strategy: Strategy::RcT,
            ..RenderSettings::default()
        },
    );
    for strategy in [Strategy::RcS, Strategy::RcSDistance] {
        let (_, rcs) = render(
            &mut r,
            &camera,
            RenderSettings {
                strategy,
                ..RenderSettings::default()
            },
        );
        eprintln!("{strategy:?}: {rcs:?} vs RC-t {rct:?}");
        assert!(
            rcs.samples * 4 < rct.samples,
            "{strategy:?}: {rcs:?} vs RC-t {rct:?}"
        );
        assert!(rcs.leaps > 0);
    }
}

/// Each mode leaps by its own default block edge (`settings::default_block_vox`): MIP's octree
/// by 16³ blocks, so a default MIP frame counts what an explicit `--block 16` frame counts, and
/// asks its structure less often than with 4³ blocks, for RC-t's image.
#[test]
fn mip_leaps_by_its_default_block_edge() {
    let volume = synthetic::vessel_tree(96, 3).expect("vessels");
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let render_with = |r: &mut VolumeRenderer, strategy, block_vox| {
        let settings = RenderSettings {
            mode: Mode::Mip,
            path: RenderPath::Fragment,
            strategy,
            block_vox,
            ..RenderSettings::default()
        };
        render(r, &camera, settings)
    };
    let (rct, _) = render_with(&mut r, Strategy::RcT, None);
    let (default, default_counts) = render_with(&mut r, Strategy::RcS, None);
    let (_, sixteen) = render_with(&mut r, Strategy::RcS, Some(16));
    let (four_image, four) = render_with(&mut r, Strategy::RcS, Some(4));
    common::assert_close("RC-s default", &default, &rct, 1.0 / 255.0, 0.0);
    common::assert_close("RC-s 4", &four_image, &rct, 1.0 / 255.0, 0.0);
    assert_eq!(
        (
            default_counts.samples,
            default_counts.lookups,
            default_counts.leaps
        ),
        (sixteen.samples, sixteen.lookups, sixteen.leaps)
    );
    assert!(default_counts.leaps > 0);
    assert!(
        default_counts.lookups < four.lookups,
        "16³: {default_counts:?}, 4³: {four:?}"
    );
}

/// The two-sided distance field: where no block can be skipped (X-ray with the window's low end
/// below every value), a ray asks the field once (at most twice) and takes its samples in one
/// cube, while the octree asks at every block it enters; both take RC-t's samples and draw its
/// image. Counted by the statistics variants' `lookups`.
#[test]
fn a_volume_with_nothing_to_skip_costs_the_field_one_lookup_per_ray() {
    let volume = odd_volume();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let render_with = |r: &mut VolumeRenderer, strategy| {
        let settings = RenderSettings {
            mode: Mode::Xray,
            // The fragment path: one invocation per ray (the compute path splits small images).
            path: RenderPath::Fragment,
            strategy,
            block_vox: Some(4),
            window: Some([-10.0, 1000.0]),
            ..RenderSettings::default()
        };
        render(r, &camera, settings)
    };
    let (rct, rct_counts) = render_with(&mut r, Strategy::RcT);
    let (octree, octree_counts) = render_with(&mut r, Strategy::RcS);
    let (field, field_counts) = render_with(&mut r, Strategy::RcSDistance);
    for (name, image, counts) in [
        ("RC-s", &octree, octree_counts),
        ("RC-s-df", &field, field_counts),
    ] {
        common::assert_close(name, image, &rct, 1.0 / 255.0, 0.0);
        assert_eq!(
            counts.samples, rct_counts.samples,
            "{name}: nothing to skip"
        );
        assert_eq!(counts.leaps, 0, "{name}");
    }
    assert!(field_counts.rays > 1000);
    // The field: one lookup per ray, and a second for the rays whose last sample, clamped to
    // the exit, lies at (not before) the cube's exit face.
    assert!(
        field_counts.lookups >= field_counts.rays && field_counts.lookups <= 2 * field_counts.rays,
        "field {} lookups for {} rays",
        field_counts.lookups,
        field_counts.rays
    );
    eprintln!(
        "lookups per ray: field {:.2}, octree {:.2}",
        field_counts.lookups as f64 / field_counts.rays as f64,
        octree_counts.lookups as f64 / octree_counts.rays as f64
    );
    // The octree: one per leaf block entered (13 blocks on the longest axis).
    assert!(
        octree_counts.lookups > 4 * octree_counts.rays,
        "octree {} lookups for {} rays",
        octree_counts.lookups,
        octree_counts.rays
    );
}

/// An isosurface ray that leaps lands on the last sample of the region it leapt (that sample
/// brackets a crossing just past the region) and takes it without asking about it again: every
/// lookup either leaps or starts the run where the surface can lie. The scene: a 64³ volume, zero
/// but for a slab at its far end (z ≥ 48), seen along +z, iso value half the slab's; each ray
/// leaps the empty space in a few regions, then asks about at most two blocks at the slab's face
/// (one holding the crossing, and perhaps the one before, which its one-voxel margin makes not
/// empty). Asking again at each landing sample (as before) costs one more lookup per leap. Both
/// leaping strategies draw RC-t's image.
#[test]
fn an_isosurface_ray_asks_once_per_region() {
    let (rct, leaping) = slab_isosurfaces(|z| if z >= 48 { 100.0 } else { 0.0 });
    for (strategy, image, counts) in leaping {
        let name = strategy.label();
        common::assert_close(name, &image, &rct, 1.0 / 255.0, 0.0);
        assert!(counts.rays > 1000, "{name}: {} rays", counts.rays);
        assert!(
            counts.leaps >= counts.rays,
            "{name}: {} leaps for {} rays",
            counts.leaps,
            counts.rays
        );
        assert!(
            counts.lookups <= counts.leaps + 2 * counts.rays,
            "{name}: {} lookups for {} leaps of {} rays",
            counts.lookups,
            counts.leaps,
            counts.rays
        );
        eprintln!(
            "{name}: per ray {:.2} lookups, {:.2} leaps",
            counts.lookups as f64 / counts.rays as f64,
            counts.leaps as f64 / counts.rays as f64
        );
    }
}

/// RC-t's isosurface image and each leaping strategy's (image, counters) of a 64³ volume whose
/// value depends on z only (`value(z)`), seen along +z, iso value 50, 4³ blocks, one invocation
/// per ray (the compute path splits small images).
#[allow(clippy::type_complexity)]
fn slab_isosurfaces(
    value: impl Fn(u32) -> f32,
) -> (
    leapview::imaging::ImageF32,
    Vec<(Strategy, leapview::imaging::ImageF32, FrameCounters)>,
) {
    let n = 64u32;
    let v: Vec<f32> = (0..n * n * n).map(|i| value(i / (n * n))).collect();
    let volume = Volume::new(
        "slabs",
        [n, n, n],
        [1.0, 1.0, 1.0],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid");
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::PlusZ.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let mut render_with = |strategy| {
        let settings = RenderSettings {
            mode: Mode::Iso,
            path: RenderPath::Fragment,
            strategy,
            block_vox: Some(4),
            iso: IsoSettings {
                value: Some(50.0),
                ..IsoSettings::default()
            },
            ..RenderSettings::default()
        };
        render(&mut r, &camera, settings)
    };
    let (rct, _) = render_with(Strategy::RcT);
    let leaping = [Strategy::RcS, Strategy::RcSDistance]
        .into_iter()
        .map(|strategy| {
            let (image, counts) = render_with(strategy);
            (strategy, image, counts)
        })
        .collect();
    (rct, leaping)
}

/// A ray that enters where the volume lies above the iso value (100 up to z = 31, 0 from z = 32,
/// seen from the front) finds the surface where the volume turns below, with both leaping
/// strategies as with RC-t. (An exactness check of leaping from a start above the iso value; the
/// blocks at z = 32 hold both sides, so it passed before the rule that a ray without a side asks
/// nothing, too: the case that needs the rule is the gap of missing voxels, below.)
#[test]
fn a_ray_that_starts_above_the_iso_value_finds_the_surface_below() {
    surface_drawn_as_rc_t_draws_it(|z| if z < 32 { 100.0 } else { 0.0 });
}

/// A crossing past missing samples: 100 up to z = 19, non-finite from z = 20 to 39, 0 from z = 40.
/// Plain ray casting brackets the crossing with the last finite sample before the gap (the
/// missing ones leave the side as it was) and the first after it; the leaping strategies skip
/// the gap (it holds no finite voxel) and must bracket it with the same two samples.
#[test]
fn a_crossing_past_missing_samples_is_bracketed_as_rc_t_brackets_it() {
    surface_drawn_as_rc_t_draws_it(|z| match z {
        0..20 => 100.0,
        20..40 => f32::NAN,
        _ => 0.0,
    });
}

/// RC-t draws an isosurface of the z-layered volume `value(z)` (`slab_isosurfaces`), and both
/// leaping strategies leap and draw the same image.
fn surface_drawn_as_rc_t_draws_it(value: impl Fn(u32) -> f32) {
    let (rct, leaping) = slab_isosurfaces(value);
    let lit = rct
        .pixels
        .iter()
        .filter(|p| p[0] + p[1] + p[2] > 0.05)
        .count();
    assert!(lit > 1000, "RC-t draws the surface: {lit} pixels");
    for (strategy, image, counts) in leaping {
        let name = strategy.label();
        common::assert_close(name, &image, &rct, 1.0 / 255.0, 0.0);
        assert!(counts.leaps > 0, "{name} leaps");
    }
}
