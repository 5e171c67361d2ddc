//! Telling a dropped file's labels from an image by its header and name alone (3D Slicer goes by
//! the name, ITK-SNAP asks): a segmentation format, a NIfTI header's label intent or a names
//! file beside whole-number samples make it labels; whole numbers whose name says so or that lie
//! on the grid of the image on screen are asked about; anything else is an image.

use std::path::Path;

use crate::volume::load::header_facts;

/// Words of a file name (split at anything but letters) that name a segmentation.
const LABEL_WORDS: [&str; 17] = [
    "seg",
    "segs",
    "segmentation",
    "segmentations",
    "label",
    "labels",
    "labelmap",
    "mask",
    "masks",
    "parc",
    "parcels",
    "parcellation",
    "aseg",
    "aparc",
    "atlas",
    "roi",
    "rois",
];

/// What a dropped file looks like beside the image on screen.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DropGuess {
    /// The image's labels, and why.
    Labels(String),
    /// Labels or an image: the user is asked; why it may be labels.
    Ask(String),
    /// An image to open.
    Image,
}

/// Guesses what the file at `path` is, dropped over an image of `image_dims` voxels.
pub fn guess_dropped(path: &Path, image_dims: [u32; 3]) -> DropGuess {
    if super::is_segmentation_file(path) {
        return DropGuess::Labels("it is a segmentation file".into());
    }
    let Some(facts) = header_facts(path) else {
        return DropGuess::Image;
    };
    if facts.label_intent {
        return DropGuess::Labels("its NIfTI header says it holds labels".into());
    }
    if facts.segments {
        return DropGuess::Labels("its header describes segments".into());
    }
    if !facts.whole {
        return DropGuess::Image;
    }
    if let Some(names) = super::read::beside(path) {
        let name = names.file_name().map(|n| n.to_string_lossy().into_owned());
        return DropGuess::Labels(format!(
            "their names are beside it ({})",
            name.unwrap_or_default()
        ));
    }
    // A name alone is asked about: a dataset's name may hold such a word ("seg3D").
    if let Some(word) = label_word(path) {
        return DropGuess::Ask(format!(
            "its name says '{word}' and its samples are whole numbers"
        ));
    }
    if facts.dims == image_dims.map(u64::from) {
        return DropGuess::Ask("its samples are whole numbers on the image's grid".into());
    }
    DropGuess::Image
}

/// The word of the file's name that names a segmentation.
fn label_word(path: &Path) -> Option<String> {
    let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
    name.split(|c: char| !c.is_ascii_alphabetic())
        .find(|word| LABEL_WORDS.contains(word))
        .map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_says_labels_by_the_start_of_a_word() {
        let word = |n: &str| label_word(Path::new(n));
        assert_eq!(word("BraTS2021_00000_seg.nii.gz").as_deref(), Some("seg"));
        assert_eq!(word("ct_labels.nrrd").as_deref(), Some("labels"));
        assert_eq!(
            word("mr_head_t1_seg3d_parcels.nii.gz").as_deref(),
            Some("seg")
        );
        assert_eq!(word("liver-mask.mha").as_deref(), Some("mask"));
        assert_eq!(word("aparc+aseg.nii").as_deref(), Some("aparc"));
        // A word that only begins like one is not one: a masked (skull-stripped) image.
        assert_eq!(word("chest_ct.nii.gz"), None);
        assert_eq!(word("t1_brain_masked.nii"), None);
        assert_eq!(word("segment_7.nrrd"), None);
        assert_eq!(word("t1_mprage.nii.gz"), None);
    }
}
