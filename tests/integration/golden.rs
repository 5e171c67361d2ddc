//! Golden images rendered on lavapipe: generated volumes and real scans, several views,
//! transfer functions and both paths. `LEAPVIEW_BLESS=1 cargo test --test integration golden::`
//! rewrites them (then look at every image before committing).

use crate::common;

use glam::DVec3;
use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::settings::{RenderPath, RenderSettings, Strategy};
use leapview::transfer::TransferFunction;
use leapview::transfer::presets::preset;
use leapview::volume::synthetic::{self, Axis};
use leapview::volume::{Volume, load_volume};

struct Case {
    name: &'static str,
    view: ViewPreset,
    kind: ProjectionKind,
    tf: TransferFunction,
    path: RenderPath,
}

fn render_cases(volume: &Volume, cases: Vec<Case>, adjust: impl Fn(&mut Camera)) {
    let mut r = common::renderer();
    r.set_volume(volume).expect("upload");
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    for case in cases {
        let (dir, up) = case.view.direction_and_up();
        let mut camera = Camera::framing(&bounds, dir, up, case.kind);
        adjust(&mut camera);
        r.set_transfer_function(&case.tf);
        let settings = RenderSettings {
            path: case.path,
            strategy: Strategy::RcT,
            ..RenderSettings::default()
        };
        let image = r
            .render_image(&camera, [128, 128], &settings)
            .expect("render");
        common::assert_golden(case.name, &image);
    }
}

fn case(
    name: &'static str,
    view: ViewPreset,
    kind: ProjectionKind,
    tf: &str,
    path: RenderPath,
) -> Case {
    Case {
        name,
        view,
        kind,
        tf: preset(tf).expect("preset"),
        path,
    }
}

#[test]
fn shepp_logan_phantom() {
    use ProjectionKind::*;
    use RenderPath::*;
    let volume = synthetic::shepp_logan(128).expect("phantom");
    render_cases(
        &volume,
        vec![
            case(
                "shepp-logan-bone-oblique",
                ViewPreset::Oblique,
                Perspective,
                "ct-bone",
                Compute,
            ),
            case(
                "shepp-logan-soft-tissue-plus-x",
                ViewPreset::PlusX,
                Orthographic,
                "ct-soft-tissue",
                Fragment,
            ),
            case(
                "shepp-logan-soft-tissue-minus-z",
                ViewPreset::MinusZ,
                Perspective,
                "ct-soft-tissue",
                Compute,
            ),
        ],
        |_| {},
    );
}

#[test]
fn shepp_logan_from_inside() {
    let volume = synthetic::shepp_logan(128).expect("phantom");
    render_cases(
        &volume,
        vec![case(
            "shepp-logan-inside",
            ViewPreset::PlusY,
            ProjectionKind::Perspective,
            "ct-soft-tissue",
            RenderPath::Fragment,
        )],
        // The eye in the brain, 30 mm behind the centre, looking forward.
        |c| {
            c.eye = c.target - DVec3::new(0.0, 30.0, 0.0);
        },
    );
}

#[test]
fn vessel_tree() {
    let volume = synthetic::vessel_tree(128, 1).expect("vessels");
    render_cases(
        &volume,
        vec![case(
            "vessel-tree-oblique",
            ViewPreset::Oblique,
            ProjectionKind::Perspective,
            "mr-angio",
            RenderPath::Compute,
        )],
        |_| {},
    );
}

#[test]
fn checkerboard_shows_axes_and_anisotropic_spacing() {
    let volume =
        synthetic::checkerboard([24, 16, 8], [1.0, 1.5, 3.0], [6, 4, 2], 0.0, 1.0).expect("board");
    let mut tf = TransferFunction::grey_ramp();
    tf.opacity = vec![[0.0, 0.0], [1.0, 0.3]];
    let ramp = synthetic::ramp([32, 32, 32], [1.0; 3], Axis::X).expect("ramp");
    render_cases(
        &volume,
        vec![Case {
            name: "checkerboard-oblique",
            view: ViewPreset::Oblique,
            kind: ProjectionKind::Perspective,
            tf: tf.clone(),
            path: RenderPath::Compute,
        }],
        |_| {},
    );
    render_cases(
        &ramp,
        vec![Case {
            name: "ramp-x-minus-y",
            view: ViewPreset::MinusY,
            kind: ProjectionKind::Orthographic,
            tf,
            path: RenderPath::Fragment,
        }],
        |_| {},
    );
}

#[test]
fn real_scans() {
    let dir = common::data_dir();
    let load =
        |f: &str| load_volume(&dir.join(f), &Default::default()).unwrap_or_else(|e| panic!("{e}"));
    render_cases(
        &load("mr_head_t1_seg3d_160x232x160_uint8.nrrd"),
        vec![case(
            "mr-head-t1-mr-default-minus-x",
            ViewPreset::MinusX,
            ProjectionKind::Perspective,
            "mr-default",
            RenderPath::Compute,
        )],
        |_| {},
    );
    render_cases(
        &load("cta_stent_128x128x256_int16.nrrd"),
        vec![case(
            "cta-stent-grey-oblique",
            ViewPreset::Oblique,
            ProjectionKind::Perspective,
            "grey-ramp",
            RenderPath::Fragment,
        )],
        |_| {},
    );
}
