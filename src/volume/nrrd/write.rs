//! Writing a volume as an attached-header, gzip-encoded NRRD (`NRRD0004`) that 3D Slicer, ITK,
//! teem and LeapView read: stored type and samples unchanged, spacing (as `space directions`
//! where the orientation is known), value scaling and modality as key/values.

use std::io::Write;
use std::path::Path;

use flate2::Compression;
use flate2::write::GzEncoder;

use crate::volume::{
    model::Volume, orientation::Direction, samples::Samples, samples::ValueMapping,
};

/// Writes `volume` to `path`; `comment` becomes a `#` line (provenance). A `.nhdr` path gets a
/// detached header and the samples raw, little-endian, in a file of the same name ending in
/// `.raw` beside it (which also opens as a headerless raw file); any other, one gzip NRRD.
pub fn write_nrrd(volume: &Volume, path: &Path, comment: &str) -> std::io::Result<()> {
    let samples = volume
        .whole_samples("writing NRRD")
        .map_err(std::io::Error::other)?;
    let detached = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nhdr"));
    if detached {
        let raw = path.with_extension("raw");
        let name = raw
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mut out = std::io::BufWriter::new(std::fs::File::create(&raw)?);
        write_samples(samples, &mut out)?;
        out.flush()?;
        let text = header(volume, comment, &Encoding::RawIn(&name));
        return std::fs::write(path, text);
    }
    let file = std::fs::File::create(path)?;
    let mut out = std::io::BufWriter::new(file);
    out.write_all(header(volume, comment, &Encoding::Gzip).as_bytes())?;
    let mut gz = GzEncoder::new(out, Compression::new(6));
    write_samples(samples, &mut gz)?;
    gz.finish()?.flush()
}

/// Where and how the samples are stored.
pub enum Encoding<'a> {
    /// Gzip, after the header in the same file.
    Gzip,
    /// Raw, in the named file beside the header.
    RawIn(&'a str),
}

/// The header text, up to and including the blank line that ends it.
pub fn header(volume: &Volume, comment: &str, encoding: &Encoding) -> String {
    let [x, y, z] = volume.dims();
    let [sx, sy, sz] = volume.spacing_mm();
    let mut h = String::from("NRRD0004\n");
    for line in comment.lines() {
        h += &format!("# {line}\n");
    }
    h += &format!("type: {}\n", volume.scalar_type().name());
    h += "dimension: 3\n";
    h += &format!("sizes: {x} {y} {z}\n");
    match volume.orientation() {
        Some(o) => {
            let spacing = [sx, sy, sz];
            let columns: Vec<String> = (0..3)
                .map(|a| {
                    let v = ras_vector(o.axes[a]).map(|c| c * spacing[a]);
                    format!("({},{},{})", v[0], v[1], v[2])
                })
                .collect();
            h += "space: right-anterior-superior\n";
            h += &format!("space directions: {}\n", columns.join(" "));
            h += "space units: \"mm\" \"mm\" \"mm\"\n";
        }
        None => h += &format!("spacings: {sx} {sy} {sz}\n"),
    }
    h += "kinds: domain domain domain\n";
    if volume.scalar_type().size_bytes() > 1 {
        h += "endian: little\n";
    }
    match encoding {
        Encoding::Gzip => h += "encoding: gzip\n",
        Encoding::RawIn(name) => h += &format!("encoding: raw\ndata file: {name}\n"),
    }
    let m = volume.mapping();
    if m != ValueMapping::IDENTITY {
        h += &format!(
            "nifti_scl_slope:={}\nnifti_scl_inter:={}\n",
            m.slope, m.intercept
        );
    }
    if let Some(modality) = volume.modality() {
        h += &format!("modality:={}\n", modality.code());
    }
    h + "\n"
}

/// The unit vector of `d` in RAS coordinates.
fn ras_vector(d: Direction) -> [f64; 3] {
    match d {
        Direction::Right => [1.0, 0.0, 0.0],
        Direction::Left => [-1.0, 0.0, 0.0],
        Direction::Anterior => [0.0, 1.0, 0.0],
        Direction::Posterior => [0.0, -1.0, 0.0],
        Direction::Superior => [0.0, 0.0, 1.0],
        Direction::Inferior => [0.0, 0.0, -1.0],
    }
}

/// The samples, little-endian, x fastest, in chunks of about a megabyte.
fn write_samples(samples: &Samples, out: &mut impl Write) -> std::io::Result<()> {
    macro_rules! put {
        ($v:expr, $size:expr) => {{
            let mut buf = Vec::with_capacity(1 << 20);
            for chunk in $v.chunks((1 << 20) / $size) {
                buf.clear();
                for s in chunk {
                    buf.extend_from_slice(&s.to_le_bytes());
                }
                out.write_all(&buf)?;
            }
            Ok(())
        }};
    }
    match samples {
        Samples::U8(v) => out.write_all(v),
        Samples::I8(v) => put!(v, 1),
        Samples::U16(v) => put!(v, 2),
        Samples::I16(v) => put!(v, 2),
        Samples::U32(v) => put!(v, 4),
        Samples::I32(v) => put!(v, 4),
        Samples::F32(v) => put!(v, 4),
        Samples::F64(v) => put!(v, 8),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::synthetic::{shepp_logan, vessel_tree};
    use crate::volume::{
        load::LoadOptions, load::load_volume, modality::Modality, orientation::Orientation,
    };

    fn round_trip(volume: &Volume, name: &str) -> Volume {
        let dir = std::env::temp_dir().join(format!("leapview-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join(name);
        write_nrrd(volume, &path, "a test\nof two lines").expect("write");
        let back = load_volume(&path, &LoadOptions::default()).expect("read back");
        let _ = std::fs::remove_file(&path);
        back
    }

    #[test]
    fn a_detached_header_and_its_raw_samples_read_back_unchanged() {
        let dir = std::env::temp_dir().join(format!("leapview-nhdr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let phantom = shepp_logan(20).expect("phantom");
        let path = dir.join("phantom.nhdr");
        write_nrrd(&phantom, &path, "detached").expect("write");
        let back = load_volume(&path, &LoadOptions::default()).expect("read back");
        assert_eq!(back.samples(), phantom.samples());
        assert_eq!(back.spacing_mm(), phantom.spacing_mm());
        assert_eq!(back.orientation(), phantom.orientation());
        // The samples alone open as a raw file with the layout on the command line.
        let raw = LoadOptions {
            raw: Some(crate::volume::raw::RawParams {
                dims: [20; 3],
                scalar_type: crate::volume::samples::ScalarType::I16,
                spacing_mm: phantom.spacing_mm(),
                big_endian: false,
            }),
            ..LoadOptions::default()
        };
        let samples = load_volume(&dir.join("phantom.raw"), &raw).expect("raw");
        assert_eq!(samples.samples(), phantom.samples());
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn what_is_written_reads_back_unchanged() {
        let phantom = shepp_logan(24).expect("phantom");
        let back = round_trip(&phantom, "phantom.nrrd");
        assert_eq!(back.samples(), phantom.samples());
        assert_eq!(back.dims(), phantom.dims());
        assert_eq!(back.spacing_mm(), phantom.spacing_mm());
        assert_eq!(back.modality(), phantom.modality());
        let tree = vessel_tree(20, 3).expect("tree");
        let back = round_trip(&tree, "tree.nrrd");
        assert_eq!(back.samples(), tree.samples());
    }

    #[test]
    fn orientation_scaling_and_floats_survive() {
        let samples = Samples::F32(vec![0.5, f32::NAN, -2.0, 7.25, 1e-3, 3.0, 4.0, 5.0]);
        let mapping = ValueMapping {
            slope: 2.5,
            intercept: -1024.0,
        };
        let o = Orientation {
            axes: [Direction::Left, Direction::Posterior, Direction::Superior],
            source: crate::volume::orientation::OrientationSource::Header,
        };
        let v = Volume::new("f", [2, 2, 2], [0.5, 0.75, 2.0], samples, mapping)
            .expect("volume")
            .with_orientation(Some(o))
            .with_modality(Some(Modality::Mr { angio: true }));
        let back = round_trip(&v, "float.nrrd");
        let (Samples::F32(a), Samples::F32(b)) = (
            v.samples().expect("in memory"),
            back.samples().expect("in memory"),
        ) else {
            panic!("float samples")
        };
        assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()));
        assert_eq!(back.mapping(), mapping);
        assert_eq!(back.orientation(), Some(o));
        assert_eq!(back.spacing_mm(), [0.5, 0.75, 2.0]);
        assert_eq!(back.modality(), Some(&Modality::Mr { angio: true }));
    }
}
