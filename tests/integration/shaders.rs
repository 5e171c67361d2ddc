//! Every pipeline variant's WGSL, validated with naga without a GPU, and every GPU struct's
//! layout checked field by field against naga's reflection of its WGSL twin.

use leapview::render::PipelineKey;
use leapview::render::gpu_data::layouts;
use leapview::render::shader::{compose, module_names};

fn validate(name: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    module
}

#[test]
fn every_variant_validates() {
    for key in PipelineKey::all() {
        let source = key.source().unwrap_or_else(|e| panic!("{key:?}: {e}"));
        validate(&format!("{key:?}"), &source);
    }
    for entry in [
        "entry/proxy_passes.wgsl",
        "entry/accumulate.wgsl",
        "entry/slice.wgsl",
        "build/minmax.wgsl",
        "build/emptiness.wgsl",
        "build/distance.wgsl",
    ] {
        validate(entry, &compose(entry, &[]).expect("composes"));
    }
}

#[test]
fn every_module_is_used_and_composes_alone() {
    for name in module_names() {
        compose(name, &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

#[test]
fn statistics_code_only_in_statistics_variants() {
    for key in PipelineKey::all() {
        let module = validate(&format!("{key:?}"), &key.source().expect("composes"));
        let writable_storage = module.global_variables.iter().any(|(_, g)| {
            matches!(g.space, naga::AddressSpace::Storage { access } if access.contains(naga::StorageAccess::STORE))
        });
        let atomics_in = |space: naga::AddressSpace| {
            module
                .global_variables
                .iter()
                .any(|(_, g)| g.space == space && holds_atomics(&module, g.ty))
        };
        assert_eq!(
            writable_storage, key.stats,
            "{key:?}: writable storage exactly in stats variants"
        );
        assert_eq!(
            atomics_in(naga::AddressSpace::Storage {
                access: naga::StorageAccess::LOAD | naga::StorageAccess::STORE
            }),
            key.stats,
            "{key:?}: counter atomics exactly in stats variants"
        );
        // The parts of a split ray tell each other where one stopped, in workgroup memory.
        assert_eq!(
            atomics_in(naga::AddressSpace::WorkGroup),
            key.split && key.strategy.terminates_early(),
            "{key:?}: workgroup atomics exactly in split variants that stop early"
        );
        let leap_reads = module
            .global_variables
            .iter()
            .any(|(_, g)| g.name.as_deref() == Some("node_empty"));
        assert_eq!(
            leap_reads,
            key.strategy.leaps(),
            "{key:?}: leaping data exactly in leaping variants"
        );
    }
}

/// Names of the functions in a module.
fn function_names(module: &naga::Module) -> Vec<String> {
    module
        .functions
        .iter()
        .filter_map(|(_, f)| f.name.clone())
        .collect()
}

/// Number of texture reads (sample or load) over all functions.
fn texture_reads(module: &naga::Module) -> usize {
    module
        .functions
        .iter()
        .map(|(_, f)| &f.expressions)
        .chain(module.entry_points.iter().map(|e| &e.function.expressions))
        .flat_map(|exprs| exprs.iter())
        .filter(|(_, e)| {
            matches!(
                e,
                naga::Expression::ImageSample { .. } | naga::Expression::ImageLoad { .. }
            )
        })
        .count()
}

#[test]
fn variants_carry_only_the_effects_their_scene_needs() {
    use leapview::settings::Mode;
    use leapview::settings::effects::{LabelView, Shading};
    for key in PipelineKey::all() {
        let module = validate(&format!("{key:?}"), &key.source().expect("composes"));
        let names = function_names(&module);
        let has = |f: &str| names.iter().any(|n| n == f);
        // Labels drawn as surfaces are lit whatever the image's shading (shade.wgsl comes with
        // them).
        let image_lit = key.shading == Shading::Phong;
        let lit = image_lit || key.labels.surfaces();
        let labelled = key.labels != LabelView::Off;
        assert_eq!(
            has("labels_at"),
            labelled,
            "{key:?}: label reads exactly in variants showing labels"
        );
        assert_eq!(
            has("gradient"),
            lit,
            "{key:?}: gradients exactly in lit variants"
        );
        assert_eq!(
            has("phong"),
            lit,
            "{key:?}: lighting code exactly in lit variants"
        );
        let projection = matches!(
            key.mode,
            Mode::Mip | Mode::MinIp | Mode::Xray | Mode::XrayAttenuation
        );
        if projection {
            assert!(!image_lit, "{key:?}: MIP, MinIP and X-ray are never lit");
        }
        // (Surfaces over a projection read the mask and the labels where they find one:
        // tests/integration/label_surfaces.rs.)
        if projection && !key.labels.surfaces() {
            // The loop's one volume read, the table read of MIP colours, the exit (and entry)
            // point loads, and the texel loads of a sample where a non-finite voxel takes part
            // (`sample_finite`), and with labels the label and colour-table loads of the cut
            // and of the tint (two each): no gradient reads hide elsewhere.
            let label_reads = if labelled { 4 } else { 0 };
            assert!(
                texture_reads(&module) <= 5 + label_reads,
                "{key:?}: {} texture reads",
                texture_reads(&module)
            );
        }
        let leaps = names.iter().any(|n| n == "leap_from");
        assert_eq!(
            leaps,
            key.strategy.leaps(),
            "{key:?}: leaping code exactly in RC-s variants"
        );
    }
}

/// A naga type as WGSL spells it (the spelling `WgslType` uses on the Rust side).
fn wgsl_spelling(module: &naga::Module, ty: naga::Handle<naga::Type>) -> String {
    let scalar = |s: naga::Scalar| match (s.kind, s.width) {
        (naga::ScalarKind::Float, 4) => "f32".to_string(),
        (naga::ScalarKind::Uint, 4) => "u32".to_string(),
        (naga::ScalarKind::Sint, 4) => "i32".to_string(),
        other => format!("{other:?}"),
    };
    match &module.types[ty].inner {
        naga::TypeInner::Scalar(s) => scalar(*s),
        naga::TypeInner::Vector { size, scalar: s } => {
            format!("vec{}<{}>", *size as u8, scalar(*s))
        }
        naga::TypeInner::Matrix {
            columns,
            rows,
            scalar: s,
        } => format!("mat{}x{}<{}>", *columns as u8, *rows as u8, scalar(*s)),
        naga::TypeInner::Array {
            base,
            size: naga::ArraySize::Constant(n),
            ..
        } => format!("array<{}, {n}>", wgsl_spelling(module, *base)),
        other => format!("{other:?}"),
    }
}

#[test]
fn every_gpu_struct_matches_its_wgsl_twin_field_by_field() {
    let all = layouts();
    assert!(
        all.len() >= 6,
        "the uniform and parameter blocks are listed"
    );
    for rust in all {
        let source = compose(rust.module, &[]).expect("composes");
        let module = validate(rust.module, &source);
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(rust.wgsl_name))
            .unwrap_or_else(|| panic!("no struct {} in {}", rust.wgsl_name, rust.module));
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!("{} is not a struct", rust.wgsl_name);
        };
        let wgsl: Vec<(String, usize, String)> = members
            .iter()
            .map(|m| {
                (
                    m.name.clone().unwrap_or_default(),
                    m.offset as usize,
                    wgsl_spelling(&module, m.ty),
                )
            })
            .collect();
        let ours: Vec<(String, usize, String)> = rust
            .fields
            .iter()
            .map(|f| (f.name.to_string(), f.offset, f.wgsl_type.clone()))
            .collect();
        assert_eq!(
            ours, wgsl,
            "{} (Rust) against {} in {}: (name, offset, type) per field",
            rust.rust_name, rust.wgsl_name, rust.module
        );
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).expect("layout");
        assert_eq!(
            layouter[handle].size as usize, rust.size,
            "{} size",
            rust.rust_name
        );
    }
}

/// Whether type `ty` is or holds atomics.
fn holds_atomics(module: &naga::Module, ty: naga::Handle<naga::Type>) -> bool {
    match &module.types[ty].inner {
        naga::TypeInner::Atomic(_) => true,
        naga::TypeInner::Array { base, .. } => holds_atomics(module, *base),
        naga::TypeInner::Struct { members, .. } => {
            members.iter().any(|m| holds_atomics(module, m.ty))
        }
        _ => false,
    }
}
