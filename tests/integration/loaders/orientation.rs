//! Anatomical orientation from headers: NIfTI sform and qform (with qfac), NRRD `space` and
//! `space directions`, files without one, and the NIfTI originals of `../shared/data` (RAS, as
//! their README says).

use leapview::volume::{ScalarType, Volume};

use crate::common::{NiftiSpec, TempDir, load_ok, nrrd_file, nrrd_lines, samples_of, to_bytes};

const DIMS: [u32; 3] = [4, 3, 2];

/// The rows of an sform.
type Sform = Option<[[f32; 4]; 3]>;

/// A `.nii` file of [`DIMS`] with `sform` and its header patched by `patch` (offsets of
/// nifti1.h); returns the header's orientation code.
fn nifti(
    dir: &TempDir,
    name: &str,
    pixdim0: f32,
    sform: Sform,
    patch: &[(usize, Vec<u8>)],
) -> String {
    let mut spec = NiftiSpec::new(ScalarType::U8, DIMS, [1.0, 1.0, 1.0]);
    spec.pixdim[0] = pixdim0;
    spec.sform = sform;
    let mut bytes = spec.file(&to_bytes(&samples_of(ScalarType::U8, 24), false));
    for (offset, data) in patch {
        bytes[*offset..offset + data.len()].copy_from_slice(data);
    }
    let path = dir.write(name, &bytes);
    file_code(&load_ok(&path))
}

/// The header's orientation code (`none` without one), after checking that a mirrored one came
/// back reversed along i, as a right-handed picture of the patient.
fn file_code(v: &Volume) -> String {
    let Some(file) = v.file_orientation() else {
        assert!(!v.reversed_i());
        return "none".into();
    };
    let here = v.orientation().expect("orientation");
    assert!(!here.is_mirrored(), "{} loaded mirrored", file.code());
    assert_eq!(v.reversed_i(), file.is_mirrored(), "{}", file.code());
    assert_eq!(here == file, !file.is_mirrored(), "{}", file.code());
    file.code()
}

fn f32s(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

const QFORM_CODE: usize = 252;
const QUATERN_B: usize = 256;

#[test]
fn nifti_sform_is_preferred_and_qform_honours_qfac() {
    let dir = TempDir::new("orientation-nifti");
    assert_eq!(nifti(&dir, "none.nii", 1.0, None, &[]), "none");
    // sform: i → −x (left), j → +z (superior), k → −y (posterior), with 0.8 mm on i.
    let sform = Some([
        [-0.8, 0.0, 0.0, 10.0],
        [0.0, 0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
    ]);
    assert_eq!(nifti(&dir, "sform.nii", 1.0, sform, &[]), "LSP");
    // qform: 180° about z (b = c = 0, d = 1) turns i to the left and j to the back: LPS; with
    // qfac = −1 (pixdim[0] < 0) k flips too: LPI.
    let qform = vec![
        (QFORM_CODE, 1i16.to_le_bytes().to_vec()),
        (QUATERN_B, f32s(&[0.0, 0.0, 1.0])),
    ];
    assert_eq!(nifti(&dir, "qform.nii", 1.0, None, &qform), "LPS");
    assert_eq!(nifti(&dir, "qfac.nii", -1.0, None, &qform), "LPI");
    // With both, the sform wins (as nibabel and ITK).
    assert_eq!(nifti(&dir, "both.nii", 1.0, sform, &qform), "LSP");
}

#[test]
fn nrrd_space_and_directions_give_the_orientation() {
    let dir = TempDir::new("orientation-nrrd");
    let data = to_bytes(&samples_of(ScalarType::U8, 24), false);
    let code = |name: &str, extra: &[&str]| {
        let mut lines = nrrd_lines(ScalarType::U8, DIMS, "raw", false);
        lines.extend(extra.iter().map(|s| s.to_string()));
        let lines: Vec<&str> = lines.iter().map(String::as_str).collect();
        let path = dir.write(name, &nrrd_file(&lines, &data));
        file_code(&load_ok(&path))
    };
    let identity = "space directions: (1,0,0) (0,1,0) (0,0,1)";
    assert_eq!(
        code("lps.nrrd", &["space: left-posterior-superior", identity]),
        "LPS"
    );
    assert_eq!(code("ras.nrrd", &["space: RAS", identity]), "RAS");
    // Slices along y: i → superior (2 mm), j → right, k → anterior.
    let swapped = "space directions: (0,0,2) (1,0,0) (0,1,0)";
    assert_eq!(
        code("sra.nrrd", &["space: right-anterior-superior", swapped]),
        "SRA"
    );
    assert_eq!(
        load_ok(&dir.path().join("sra.nrrd")).spacing_mm(),
        [2.0, 1.0, 1.0]
    );
    // Not anatomical, or no directions: unknown.
    assert_eq!(
        code("scanner.nrrd", &["space: scanner-xyz", identity]),
        "none"
    );
    assert_eq!(code("spacings.nrrd", &["spacings: 1 1 1"]), "none");
}

#[test]
fn the_nifti_originals_are_ras() {
    let originals = crate::common::data_dir().join("originals");
    let mut seen = 0;
    for entry in std::fs::read_dir(&originals).expect("originals folder") {
        let path = entry.expect("entry").path();
        if path.to_string_lossy().ends_with(".nii.gz") {
            let o = load_ok(&path)
                .orientation()
                .expect("the originals have an sform");
            assert_eq!(o.code(), "RAS", "{}", path.display());
            seen += 1;
        }
    }
    assert!(seen >= 5, "only {seen} originals");
}

#[test]
fn a_mirrored_file_is_read_reversed_along_i() {
    // LAS (sform i → −x): a mirror image of the patient; every row comes back reversed, so that
    // voxel i here is voxel 3 − i of the file, and the orientation reads RAS.
    let dir = TempDir::new("orientation-mirrored");
    let las = Some([
        [-1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ]);
    assert_eq!(nifti(&dir, "las.nii", 1.0, las, &[]), "LAS");
    let v = load_ok(&dir.path().join("las.nii"));
    assert_eq!(v.orientation().map(|o| o.code()).as_deref(), Some("RAS"));
    let file = samples_of(ScalarType::U8, 24);
    let [nx, ny, nz] = DIMS;
    for (z, y, x) in
        (0..nz).flat_map(|z| (0..ny).flat_map(move |y| (0..nx).map(move |x| (z, y, x))))
    {
        let in_file = (nx - 1 - x + nx * (y + ny * z)) as usize;
        assert_eq!(v.value(x, y, z), file.get_f64(in_file), "voxel {x} {y} {z}");
    }
    // Not mirrored (LPS, a half turn of RAS): unchanged.
    let lps = Some([
        [-1.0, 0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ]);
    assert_eq!(nifti(&dir, "lps.nii", 1.0, lps, &[]), "LPS");
    let v = load_ok(&dir.path().join("lps.nii"));
    assert_eq!(v.samples().expect("in memory"), &file);
}
