//! UI tests without a window: the crate's own panel functions (transfer-function editor, side
//! panel, menu bar, error dialog, loading indicator) run inside an `egui_kittest` harness, are driven through the
//! AccessKit tree the way a user would (clicks, drags, keys, found by label, never by pixel
//! position, except inside the opacity canvas where a position *is* the input), and are rendered
//! with egui's wgpu renderer for image snapshots in `tests/snapshots/`.
//!
//! Why: the panels are the only code the renderer tests never reach; a widget that stops
//! editing the state, or a layout that breaks, shows up here first. The assertions check the
//! state the UI edits; the snapshots catch what the state cannot (clipping, overlap, layout).
//!
//! Update the snapshots after an intended UI change with
//! `UPDATE_SNAPSHOTS=1 cargo test --test integration ui_snapshots::`, then look at the PNGs
//! before committing.

mod harness;

use egui::accesskit::Toggled;
use egui::{Key, Modifiers};
use egui_kittest::kittest::{NodeT, Queryable};
use harness::{canvas_pos, click_at, drag, harness, harness_with, render_state};
use leapview::camera::{ProjectionKind, ViewPreset};
use leapview::settings::Strategy;
use leapview::transfer::editor::TfEditor;
use leapview::transfer::presets::preset;
use leapview::ui::layout::Layout;
use leapview::ui::panels::controls::{PanelInfo, controls_ui};
use leapview::ui::panels::dialogs::Dialogs;
use leapview::ui::panels::menu::menu_bar;
use leapview::ui::panels::tf_editor::tf_editor_ui;
use leapview::ui::{Action, ViewerState, VolumeSummary};
use leapview::volume::ValueRange;
use leapview::volume::synthetic::shepp_logan;

/// Edge of the generated phantom whose histogram and range the panels show: small enough to
/// generate in milliseconds, large enough for a histogram with the phantom's peaks.
const PHANTOM_N: u32 = 48;

/// The phantom's summary (name, range, histogram), as the window builds it after loading.
fn phantom() -> VolumeSummary {
    VolumeSummary::of(&shepp_logan(PHANTOM_N).expect("phantom"))
}

/// The transfer-function editor with what the window gives it.
struct TfPanel {
    editor: TfEditor,
    range: ValueRange,
    histogram: Vec<u64>,
    log_scale: bool,
    /// Passes in which `tf_editor_ui` reported a changed transfer function.
    reported_changes: usize,
}

fn tf_panel() -> egui_kittest::Harness<'static, TfPanel> {
    let summary = phantom();
    let panel = TfPanel {
        editor: TfEditor::new(preset("ct-bone").expect("preset")),
        range: summary.range.expect("the phantom has a value range"),
        histogram: summary.histogram,
        log_scale: true,
        reported_changes: 0,
    };
    harness([440.0, 250.0]).build_ui_state(
        |ui, p: &mut TfPanel| {
            let range = Some(p.range);
            if tf_editor_ui(
                ui,
                &mut p.editor,
                range,
                &p.histogram,
                &mut p.log_scale,
                None,
            ) {
                p.reported_changes += 1;
            }
        },
        panel,
    )
}

/// How far a point set with the mouse may be from its target, as `(value, alpha)`: half a
/// point of the canvas in each direction, since egui may place the pointer anywhere within the
/// pixel it lands on.
fn half_point(h: &egui_kittest::Harness<'_, TfPanel>) -> (f64, f64) {
    let canvas = h.get_by_label("Opacity curve").rect();
    (
        0.5 * h.state().range.width() / f64::from(canvas.width()),
        0.5 / f64::from(canvas.height()),
    )
}

#[test]
fn tf_editor_click_adds_a_point_and_undo_redo_restore_it() {
    let mut h = tf_panel();
    let original = h.state().editor.tf().clone();
    h.snapshot("tf_editor");
    assert!(h.get_by_label("Undo").accesskit_node().is_disabled());
    assert!(h.get_by_label("Redo").accesskit_node().is_disabled());

    // Mid-range at alpha 0.8: ct-bone is transparent there, so no handle is within reach and
    // the click adds a point.
    let canvas = h.get_by_label("Opacity curve").rect();
    let value = h.state().range.denormalize(0.5);
    click_at(&h, canvas_pos(canvas, h.state().range, value, 0.8));
    h.run();
    let tf = h.state().editor.tf().clone();
    assert_eq!(tf.opacity.len(), original.opacity.len() + 1, "{tf:?}");
    let added = tf
        .opacity
        .iter()
        .find(|p| !original.opacity.contains(p))
        .expect("a new point");
    let (value_tol, alpha_tol) = half_point(&h);
    assert!(
        (added[0] - value).abs() <= value_tol,
        "{added:?} vs {value}"
    );
    assert!((added[1] - 0.8).abs() <= alpha_tol, "{added:?}");
    assert_eq!(h.state().reported_changes, 1);
    assert!(!h.get_by_label("Undo").accesskit_node().is_disabled());
    h.snapshot("tf_editor_point_added");

    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(h.state().editor.tf(), &original);
    assert!(!h.get_by_label("Redo").accesskit_node().is_disabled());
    h.get_by_label("Redo").click();
    h.run();
    assert_eq!(h.state().editor.tf(), &tf);

    // Ctrl+Z works while no text field has the focus.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(h.state().editor.tf(), &original);
    assert_eq!(h.state().reported_changes, 4, "add, undo, redo, Ctrl+Z");
}

#[test]
fn tf_editor_drag_moves_a_point_as_one_undo_step() {
    let mut h = tf_panel();
    let original = h.state().editor.tf().clone();
    let range = h.state().range;
    let canvas = h.get_by_label("Opacity curve").rect();
    // ct-bone's (300 HU, 0.15) point, dragged to (500 HU, 0.4) through several moves.
    let [from_value, from_alpha] = original.opacity[2];
    assert_eq!([from_value, from_alpha], [300.0, 0.15], "ct-bone changed");
    drag(
        &h,
        canvas_pos(canvas, range, from_value, from_alpha),
        canvas_pos(canvas, range, 500.0, 0.4),
    );
    h.run();
    let tf = h.state().editor.tf().clone();
    assert_eq!(tf.opacity.len(), original.opacity.len(), "{tf:?}");
    let (value_tol, alpha_tol) = half_point(&h);
    let moved = tf.opacity[2];
    assert!((moved[0] - 500.0).abs() <= value_tol, "{moved:?}");
    assert!((moved[1] - 0.4).abs() <= alpha_tol, "{moved:?}");
    assert!(h.state().reported_changes >= 1);
    assert_eq!(tf.opacity[..2], original.opacity[..2]);
    assert_eq!(tf.opacity[3..], original.opacity[3..]);

    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(
        h.state().editor.tf(),
        &original,
        "one undo step for the whole drag"
    );
    assert!(!h.state().editor.can_undo());
}

#[test]
fn tf_editor_log_toggle_changes_the_drawing_not_the_function() {
    let mut h = tf_panel();
    let original = h.state().editor.tf().clone();
    let canvas = h.get_by_label("Opacity curve").rect();
    let log_canvas = crop(&h.render().expect("render"), canvas);
    let checkbox = h.get_by_label("log histogram");
    assert_eq!(checkbox.accesskit_node().toggled(), Some(Toggled::True));
    checkbox.click();
    h.run();
    h.remove_cursor();
    h.run();
    assert!(!h.state().log_scale);
    assert_eq!(
        h.get_by_label("log histogram").accesskit_node().toggled(),
        Some(Toggled::False)
    );
    assert_eq!(h.state().editor.tf(), &original);
    assert_eq!(h.state().reported_changes, 0);
    let linear_canvas = crop(&h.render().expect("render"), canvas);
    assert_ne!(linear_canvas, log_canvas, "the histogram was not redrawn");
}

/// The pixels of `rect` (points, at 1 pixel per point) in `image`.
fn crop(image: &image::RgbaImage, rect: egui::Rect) -> image::RgbaImage {
    let [x, y, w, h] = [rect.min.x, rect.min.y, rect.width(), rect.height()].map(|v| v as u32);
    image::imageops::crop_imm(image, x, y, w, h).to_image()
}

/// The side panel with the phantom loaded, and the actions its buttons returned.
struct SidePanel {
    state: ViewerState,
    volume: VolumeSummary,
    actions: Vec<Action>,
}

/// The side panel over `panel`'s state and volume, in a harness built from `builder`.
fn side_panel(
    builder: egui_kittest::HarnessBuilder<SidePanel>,
    panel: SidePanel,
) -> egui_kittest::Harness<'static, SidePanel> {
    builder.build_ui_state(
        |ui, p: &mut SidePanel| {
            let info = PanelInfo {
                path_used: None,
                strategy_used: None,
                volume: Some(&p.volume),
            };
            p.actions
                .extend(controls_ui(ui, &mut p.state, &info, |ui, _| {
                    ui.label("(mode, transfer-function editor, slices)");
                }));
        },
        panel,
    )
}

/// Side-panel labels of the 3D view's controls.
const THREE_D_ONLY: [&str; 5] = [
    "Quality",
    "Cropping",
    "Advanced",
    "Projection",
    "Reset view (R)",
];

/// A 2D image alone in its plane has no 3D view: the panel leaves out the renderer's quality,
/// cropping, the camera's views, background and projection, and Advanced, and keeps the
/// transfer function (it colours the slice), the slices' section and the orientation.
#[test]
fn a_2d_image_gets_no_3d_controls() {
    let panel = SidePanel {
        state: ViewerState {
            layout: Layout::Image(leapview::mpr::PlaneKind::Axial),
            ..ViewerState::default()
        },
        volume: phantom(),
        actions: Vec::new(),
    };
    let mut h = side_panel(harness([400.0, 800.0]).with_fit_contents(), panel);
    h.run();
    for gone in THREE_D_ONLY {
        assert!(
            h.query_by_label(gone).is_none(),
            "{gone} shown for a 2D image"
        );
    }
    for kept in ["Transfer function", "View", "Volume"] {
        assert!(
            h.query_by_label(kept).is_some(),
            "{kept} missing for a 2D image"
        );
    }
    // The same panel for a volume has them.
    h.state_mut().state.layout = Layout::OnePlusThree;
    h.run();
    for shown in THREE_D_ONLY {
        assert!(
            h.query_by_label(shown).is_some(),
            "{shown} missing for a volume"
        );
    }
}

#[test]
fn side_panel_edits_the_viewer_state() {
    let panel = SidePanel {
        state: ViewerState::default(),
        volume: phantom(),
        actions: Vec::new(),
    };
    // Sized to the panel, so that the snapshot shows all of it as rows are added (and changes
    // size then: regenerate it).
    let mut h = side_panel(harness([400.0, 800.0]).with_fit_contents(), panel);
    h.snapshot("side_panel");

    h.get_by_label("Transfer function").click();
    h.run();
    h.get_by_label("ct-skin").click();
    h.run();
    assert_eq!(h.state().state.preset, "ct-skin");
    assert_eq!(
        h.state().state.editor.tf(),
        &preset("ct-skin").expect("preset")
    );
    assert!(
        h.state().state.editor.can_undo(),
        "a preset is one undo step"
    );

    // The renderer's knobs are folded away under Advanced until asked for.
    assert!(h.query_by_label("RC-t").is_none());
    h.get_by_label("Advanced").click();
    h.run();
    // Unfolded, the section runs past the panel's first size.
    h.fit_contents();
    h.get_by_label("RC-t").click();
    h.get_by_label("count samples").click();
    h.run();
    h.get_by_label("developer readout").click();
    h.run();
    assert!(h.state().state.developer_readout);
    assert_eq!(h.state().state.render.strategy, Strategy::RcT);
    assert!(h.state().state.statistics);

    // The GPU memory budget: a list under Advanced; the app loads the volume again within it.
    h.get_by_label("GPU memory").click();
    h.run();
    h.get_by_label("1.0 GB").click();
    h.run();
    assert_eq!(
        h.state().actions.last(),
        Some(&Action::SetGpuBudget(Some(1_000_000_000)))
    );
    h.state_mut().actions.clear();
    // The memory an OME-Zarr store may take: likewise.
    h.get_by_label("Store memory").click();
    h.run();
    h.get_by_label("8.0 GB").click();
    h.run();
    assert_eq!(
        h.state().actions.last(),
        Some(&Action::SetRamBudget(Some(8_000_000_000)))
    );
    h.state_mut().actions.clear();

    // Projection and views need the camera: the panel hands them to the app.
    h.get_by_label("Orthographic").click();
    h.get_by_label("+x").click();
    h.get_by_label("S").click();
    h.get_by_label("Reset view (R)").click();
    h.run();
    assert_eq!(
        h.state().actions,
        [
            Action::SetProjection(ProjectionKind::Orthographic),
            Action::SetView(ViewPreset::PlusX),
            Action::ViewFrom(leapview::volume::Direction::Superior),
            Action::ResetView,
        ]
    );
    assert_eq!(h.state().state.projection, ProjectionKind::Perspective);
}

#[test]
fn orientation_controls_flip_a_file_without_orientation_and_check_typed_codes() {
    // A file without orientation (like the shared CT head): RAS is assumed, and the user says
    // its slices run from the top of the head down.
    let unoriented =
        leapview::volume::synthetic::constant([4, 4, 4], [1.0; 3], 1.0).expect("volume");
    let panel = SidePanel {
        state: ViewerState::default(),
        volume: VolumeSummary {
            from_file: true,
            ..VolumeSummary::of(&unoriented)
        },
        actions: Vec::new(),
    };
    let mut h = side_panel(harness([400.0, 900.0]), panel);
    h.run();
    // Said where the orientation is shown, with the correction unfolded under it.
    assert!(
        h.query_by_label_contains("none in the file: RAS assumed")
            .is_some()
    );
    h.get_by_label("Flip S/I").click();
    h.get_by_label("Roll +90°").click();
    h.run();
    let rai = leapview::volume::Orientation::parse_code("RAI").expect("valid");
    assert_eq!(
        h.state().actions,
        [Action::Reorient(Some(rai)), Action::Roll(90.0)]
    );
    // A code that is not one is refused with the reason, and Apply stays disabled.
    h.get_by_label("i, j, k point to").click();
    h.run();
    h.key_press_modifiers(Modifiers::COMMAND, Key::A);
    h.get_by_label("i, j, k point to").type_text("RRS");
    h.run();
    assert!(
        h.query_by_label_contains("one each of R/L, A/P and S/I")
            .is_some()
    );
    h.get_by_label("Apply").click();
    h.run();
    assert_eq!(h.state().actions.len(), 2, "an invalid code is not applied");
}

/// The menu bar's state and the actions it returned.
struct MenuBar {
    state: ViewerState,
    actions: Vec<Action>,
}

#[test]
fn menu_bar_opens_menus_and_returns_actions() {
    let bar = MenuBar {
        state: ViewerState::default(),
        actions: Vec::new(),
    };
    // Tall enough for the whole View menu: a clipped item cannot be clicked.
    let mut h = harness([420.0, 500.0]).build_ui_state(
        |ui, b: &mut MenuBar| b.actions.extend(menu_bar(ui, &mut b.state, None)),
        bar,
    );
    h.get_by_label("View").click();
    h.run();
    h.remove_cursor();
    h.run();
    h.snapshot("menu_bar_view");
    h.get_by_label("Orthographic").click();
    h.run();
    assert_eq!(
        h.state().actions,
        [Action::SetProjection(ProjectionKind::Orthographic)]
    );
    assert!(
        h.query_by_label("Controls panel").is_none(),
        "choosing closes the menu"
    );

    h.get_by_label("View").click();
    h.run();
    h.get_by_label("Controls panel").click();
    h.run();
    assert!(!h.state().state.show_controls);
    h.get_by_label("View").click();
    h.run();
    assert!(h.state().state.show_orientation_marker, "on by default");
    h.get_by_label("Orientation marker (R, A, S)").click();
    h.run();
    assert!(!h.state().state.show_orientation_marker);

    h.get_by_label("File").click();
    h.run();
    assert!(
        h.get_by_label("Recent").accesskit_node().is_disabled(),
        "no recent files yet"
    );
    h.get_by_label("Shepp–Logan phantom").click();
    h.run();
    assert_eq!(
        h.state().actions,
        [
            Action::SetProjection(ProjectionKind::Orthographic),
            Action::LoadPhantom,
        ]
    );

    // The layout toolbar beside the menus.
    h.get_by_label("2 × 2").click();
    h.run();
    assert_eq!(
        h.state().actions.last(),
        Some(&Action::SetLayout(Layout::Grid))
    );
}

#[test]
fn error_dialog_shows_the_message_on_one_line_until_ok() {
    let mut dialogs = Dialogs::default();
    // A message over several lines, as wgpu's errors come.
    dialogs.show_error(
        "cannot read /data/head.nrrd:\n  the header says 512×512×300 int16\n  but the file holds 12 MB",
    );
    let message =
        "cannot read /data/head.nrrd: the header says 512×512×300 int16 but the file holds 12 MB";
    let mut h = harness([560.0, 220.0]).build_ui_state(
        |ui, d: &mut Dialogs| {
            assert_eq!(d.ui(ui.ctx()), None, "no file chosen");
        },
        dialogs,
    );
    assert!(h.query_by_label("Something went wrong").is_some());
    assert!(h.query_by_label(message).is_some(), "{h:#?}");
    h.snapshot("error_dialog");

    h.get_by_label("OK").click();
    h.run();
    assert!(!h.state().has_error());
    assert!(h.query_by_label(message).is_none());
}

/// A dropped file that may be the labels of the image on screen: the dialog says why and opens
/// it as the answer says (Escape or Cancel: not at all).
#[test]
fn a_dropped_file_that_may_be_labels_is_asked_about() {
    use leapview::ui::panels::dialogs::Purpose;
    use std::path::PathBuf;
    let path = PathBuf::from("/data/ct_labels.nii.gz");
    let why = "its name says 'labels' and its samples are whole numbers";
    for (button, want) in [
        ("As its segmentation", Some(Purpose::Labels)),
        ("As a new image", Some(Purpose::Volume)),
        ("Cancel", None),
    ] {
        let mut dialogs = Dialogs::default();
        dialogs.ask_dropped(path.clone(), why.into());
        type State = (Dialogs, Option<(PathBuf, Purpose)>);
        let mut h = harness([560.0, 220.0]).build_ui_state(
            |ui, (d, chosen): &mut State| {
                if let Some(c) = d.ui(ui.ctx()) {
                    *chosen = Some(c);
                }
            },
            (dialogs, None),
        );
        assert!(
            h.query_by_label("Open ct_labels.nii.gz").is_some(),
            "{h:#?}"
        );
        assert!(
            h.query_by_label_contains("may be the segmentation of the image on screen")
                .is_some(),
            "{h:#?}"
        );
        if button == "Cancel" && std::env::var_os("LEAPVIEW_SAVE_IMAGES").is_some() {
            let image = h.render().expect("render");
            let out = crate::common::output_dir().join("dropped-dialog.png");
            image.save(out).expect("save");
        }
        h.get_by_label(button).click();
        h.run();
        assert_eq!(h.state().1, want.map(|p| (path.clone(), p)), "{button}");
        assert!(
            h.query_by_label("Open ct_labels.nii.gz").is_none(),
            "{button}: still open"
        );
    }
}

#[test]
fn loading_shows_a_bar_then_says_the_histogram_is_being_computed() {
    let status = |fraction| leapview::ui::loading::LoadStatus {
        label: "head.nrrd".into(),
        started: std::time::Instant::now(),
        fraction,
        generated: false,
    };
    let mut h = harness([360.0, 120.0]).build_ui_state(
        |ui, (s, cancelled): &mut (leapview::ui::loading::LoadStatus, bool)| {
            let view = ui.max_rect();
            *cancelled |= leapview::ui::view::overlay::draw_loading(ui, view, s);
        },
        (status(None), false),
    );
    assert!(h.query_by_label("reading the header…").is_some());
    h.state_mut().0 = status(Some(0.4));
    // The spinner keeps asking for repaints: step rather than run to a settled state.
    h.run_steps(2);
    assert!(h.query_by_label("reading the header…").is_none());
    assert!(h.query_by_label("read; computing the histogram…").is_none());
    h.state_mut().0 = status(Some(1.0));
    h.run_steps(2);
    assert!(h.query_by_label("read; computing the histogram…").is_some());
    h.get_by_label("Cancel").click();
    h.run_steps(2);
    assert!(h.state().1, "Cancel is reported");
}

#[test]
fn the_series_of_a_dicom_folder_are_listed_at_the_top_and_one_can_be_chosen() {
    // A folder's volume as the DICOM loader leaves it: the series it is, the others listed, and
    // what loading had to say.
    let volume = leapview::volume::synthetic::constant([4, 4, 4], [1.0; 3], 1.0)
        .expect("volume")
        .with_provenance(leapview::volume::Provenance {
            notes: vec!["about 1 slice missing between 'IM3' and 'IM4'".into()],
            series: Some(leapview::volume::dicom::SeriesFacts {
                uid: "1.2.3".into(),
                modality: "CT".into(),
                description: "Head 1.0".into(),
                date: "20261202".into(),
                ..Default::default()
            }),
            listing: vec![
                "1: CT #2 \"Head 1.0\", 120 slices, 512 x 512".into(),
                "2: CT #3 \"Scout\", 1 slice, 512 x 512".into(),
            ],
            chosen: Some(0),
            ..Default::default()
        });
    let panel = SidePanel {
        state: ViewerState::default(),
        volume: VolumeSummary {
            from_file: true,
            ..VolumeSummary::of(&volume)
        },
        actions: Vec::new(),
    };
    let mut h = side_panel(harness([400.0, 900.0]), panel);
    h.run();
    assert!(
        h.query_by_label_contains("CT · Head 1.0 · 2026-12-02")
            .is_some()
    );
    assert!(h.query_by_label_contains("about 1 slice missing").is_some());
    // The chooser shows the series on screen; its list offers the others.
    h.get_by(|n| {
        n.value().is_some_and(|v| v.contains("1: CT #2"))
            || n.label().is_some_and(|l| l.contains("1: CT #2"))
    })
    .click();
    h.run();
    h.get_by_label("2: CT #3 \"Scout\", 1 slice, 512 x 512")
        .click();
    h.run();
    assert_eq!(h.state().actions, [Action::OpenSeries(2)]);
}

/// The 2 × 2 layout's slice panes on the snapshots' own device: the shared CT-like phantom in
/// axial, coronal and sagittal planes through the crosshair (the 3D pane, which needs the window's
/// render thread, stands empty here). A click in the axial pane moves the crosshair: the coronal
/// and sagittal planes follow, the axial stays.
#[test]
fn the_2x2_layout_shows_three_slices_and_a_click_moves_the_others() {
    use leapview::render::context::GpuContext;
    use leapview::render::volume_texture::VolumeTexture;
    use leapview::ui::layout::{Pane, panes};
    use leapview::ui::slices::SliceViews;

    let rs = render_state();
    let ctx = GpuContext::new(&rs.adapter, rs.device.clone(), rs.queue.clone());
    let volume = std::sync::Arc::new(shepp_logan(64).expect("phantom"));
    let texture = VolumeTexture::upload(&ctx, &volume).expect("upload");
    let mut slices = SliceViews::new(&rs);
    slices.set_volume(
        volume,
        texture.view.clone(),
        texture.encoding.format,
        [-100.0, 100.0],
    );
    let start = slices.crosshair();
    let mut h = harness_with(
        [600.0, 600.0],
        egui_kittest::wgpu::WgpuTestRenderer::from_render_state(rs),
    )
    .build_ui_state(
        |ui, slices: &mut SliceViews| {
            slices.begin_pass();
            for (pane, rect) in panes(Layout::Grid, ui.max_rect(), 2.0) {
                let mut child = ui.new_child(egui::UiBuilder::new().max_rect(rect));
                if let Pane::Slice(kind) = pane {
                    slices.pane_ui(&mut child, kind, rect, None);
                }
            }
        },
        slices,
    );
    h.run();
    h.snapshot("layout_2x2");
    // Up and left of the axial pane's centre (its pane is the top-left quarter).
    click_at(&h, egui::pos2(100.0, 90.0));
    h.run();
    let moved = h.state().crosshair();
    let step = moved - start;
    assert!(
        step.length() > 1.0,
        "the click moved the crosshair: {start} -> {moved}"
    );
    assert!(
        step.z.abs() < 1e-9,
        "the axial plane stays where it was: {step}"
    );
}

/// An image with time points and channels (an OME-Zarr, an OME-TIFF) gets a chooser for each;
/// a step either way asks for that volume or channel, and a step past the ends is disabled.
#[test]
fn an_image_with_time_points_and_channels_has_a_chooser_for_each() {
    let index = |chosen, count| Some(leapview::volume::VolumeIndex { chosen, count });
    let volume = leapview::volume::synthetic::constant([4, 4, 4], [1.0; 3], 1.0)
        .expect("volume")
        .with_provenance(leapview::volume::Provenance {
            volumes: index(0, 3),
            channels: index(1, 2),
            ..Default::default()
        });
    let panel = SidePanel {
        state: ViewerState::default(),
        volume: VolumeSummary {
            from_file: true,
            ..VolumeSummary::of(&volume)
        },
        actions: Vec::new(),
    };
    let mut h = side_panel(harness([400.0, 900.0]), panel);
    h.run();
    assert!(h.query_by_label("Channel").is_some());
    assert_eq!(h.query_all_by_label(">").count(), 2);
    // The volume's next (the first is shown) and, the last channel shown, no channel's next.
    for i in 0..2 {
        h.query_all_by_label(">").nth(i).expect("a step").click();
        h.run();
    }
    assert_eq!(h.state().actions, [Action::OpenVolume(1)]);
    h.state_mut().actions.clear();
    // No volume before the first; the channel before the second.
    for i in 0..2 {
        h.query_all_by_label("<").nth(i).expect("a step").click();
        h.run();
    }
    assert_eq!(h.state().actions, [Action::OpenChannel(0)]);
}
