//! Every character the window's text uses must be in egui's fonts: a missing glyph is drawn as
//! an empty box (the Help menu once showed ↑/↓ so).

use std::path::Path;

/// The non-ASCII characters in the string literals of the Rust files below `dir`, with where
/// each was first seen.
fn characters_in_strings(dir: &Path, found: &mut Vec<(char, String)>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            characters_in_strings(&path, found);
            continue;
        }
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        for (n, line) in text.lines().enumerate() {
            let code = line.trim_start();
            if code.starts_with("//") {
                continue;
            }
            // Inside quotes only: comments after code and identifiers are not drawn.
            let mut inside = false;
            for c in code.chars() {
                if c == '"' {
                    inside = !inside;
                } else if inside && !c.is_ascii() && !found.iter().any(|(f, _)| *f == c) {
                    found.push((c, format!("{}:{}", path.display(), n + 1)));
                }
            }
        }
    }
}

#[test]
fn every_character_the_window_draws_is_in_its_fonts() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    for dir in ["ui", "transfer", "volume", "mpr"] {
        characters_in_strings(&root.join(dir), &mut found);
    }
    assert!(
        found.iter().any(|(c, _)| *c == '×'),
        "the scan finds the UI's text"
    );
    let ctx = egui::Context::default();
    // Fonts are loaded by the first pass.
    let mut output = ctx.run_ui(egui::RawInput::default(), |_| {});
    // Nothing is painted here: the font atlas need not reach a renderer.
    output.textures_delta.clear();
    let missing: Vec<_> = ctx.fonts_mut(|fonts| {
        found
            .iter()
            .filter(|(c, _)| {
                [
                    egui::FontId::proportional(14.0),
                    egui::FontId::monospace(14.0),
                ]
                .iter()
                .any(|font| !fonts.has_glyph(font, *c))
            })
            .cloned()
            .collect()
    });
    assert!(missing.is_empty(), "not in egui's fonts: {missing:?}");
}
