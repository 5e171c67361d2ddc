//! Which fragments of encapsulated pixel data make up which frame (PS3.5 A.4): one fragment a
//! frame, every fragment for a single frame, the Basic Offset Table's byte offsets, or, where
//! that table is empty, the frames' own ends (a JPEG, JPEG-LS or JPEG 2000 codestream ends with
//! the marker FF D9, followed at most by one byte of padding), as pydicom and GDCM find them.

/// The codestream of each of `frames` frames, from the pixel data's `fragments` and its Basic
/// Offset Table `offsets` (empty where the file gives none).
pub(crate) fn frame_streams(
    fragments: &[Vec<u8>],
    offsets: &[u32],
    frames: u32,
) -> Result<Vec<Vec<u8>>, String> {
    let frames = frames as usize;
    if frames == 1 {
        return Ok(vec![fragments.concat()]);
    }
    if fragments.len() == frames {
        return Ok(fragments.to_vec());
    }
    if fragments.len() < frames {
        return Err(format!(
            "{} fragments of pixel data for {frames} frames",
            fragments.len()
        ));
    }
    let groups = if offsets.len() == frames {
        by_offsets(fragments, offsets)?
    } else {
        by_ends(fragments)
    };
    if groups.len() != frames {
        return Err(format!(
            "the {} fragments of pixel data make {} frames where the header says {frames}",
            fragments.len(),
            groups.len()
        ));
    }
    Ok(groups)
}

/// Groups fragments by the Basic Offset Table: frame f starts at the fragment whose item starts
/// `offsets[f]` bytes after the first item (each item is an 8-byte header and its bytes).
fn by_offsets(fragments: &[Vec<u8>], offsets: &[u32]) -> Result<Vec<Vec<u8>>, String> {
    let mut starts = Vec::with_capacity(fragments.len());
    let mut at = 0u64;
    for f in fragments {
        starts.push(at);
        at += 8 + f.len() as u64;
    }
    let fragment_at = |k: usize, offset: u32| {
        starts
            .iter()
            .position(|&s| s == u64::from(offset))
            .ok_or_else(|| {
                format!(
                    "the offset table puts frame {} at {offset}, where no fragment starts",
                    k + 1
                )
            })
    };
    let mut out: Vec<Vec<u8>> = Vec::with_capacity(offsets.len());
    for (k, &offset) in offsets.iter().enumerate() {
        let first = fragment_at(k, offset)?;
        let end = match offsets.get(k + 1) {
            Some(&next) => fragment_at(k + 1, next)?,
            None => fragments.len(),
        };
        if end <= first {
            return Err(format!(
                "the offset table's entries {} and {} are out of order",
                k + 1,
                k + 2
            ));
        }
        out.push(fragments[first..end].concat());
    }
    Ok(out)
}

/// Groups fragments by where codestreams end: a fragment ending in FF D9 (or FF D9 and one
/// padding byte) closes a frame.
fn by_ends(fragments: &[Vec<u8>]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let mut current: Vec<u8> = Vec::new();
    for f in fragments {
        current.extend_from_slice(f);
        let tail = f.len().saturating_sub(3);
        if f[tail..].windows(2).any(|w| w == [0xFF, 0xD9]) {
            out.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fragments_map_to_frames_one_each_or_all_for_one_frame() {
        let f = vec![vec![1u8, 2], vec![3u8]];
        assert_eq!(
            frame_streams(&f, &[], 1).expect("one frame"),
            vec![vec![1, 2, 3]]
        );
        assert_eq!(frame_streams(&f, &[], 2).expect("two frames"), f);
        let e = frame_streams(&f, &[], 3).expect_err("three frames in two fragments");
        assert!(e.contains("2 fragments of pixel data for 3 frames"), "{e}");
    }

    #[test]
    fn frames_split_over_fragments_follow_the_offset_table_or_their_end_markers() {
        // Frame 1 in two fragments, frame 2 in one; each stream ends with FF D9 (the second
        // padded to an even length).
        let f = vec![
            vec![0xFF, 0xD8, 1, 2],
            vec![3, 0xFF, 0xD9, 0],
            vec![0xFF, 0xD8, 0xFF, 0xD9],
        ];
        let frames = [
            vec![0xFF, 0xD8, 1, 2, 3, 0xFF, 0xD9, 0],
            vec![0xFF, 0xD8, 0xFF, 0xD9],
        ];
        assert_eq!(frame_streams(&f, &[0, 24], 2).expect("offsets"), frames);
        assert_eq!(frame_streams(&f, &[], 2).expect("end markers"), frames);
        let e = frame_streams(&f, &[0, 20], 2).expect_err("an offset inside a fragment");
        assert!(e.contains("frame 2 at 20"), "{e}");
        let e = frame_streams(&f, &[0, 0], 2).expect_err("out of order");
        assert!(e.contains("out of order"), "{e}");
        let unmarked = vec![vec![1u8], vec![2u8], vec![3u8]];
        let e = frame_streams(&unmarked, &[], 2).expect_err("no end markers");
        assert!(e.contains("make 1 frames"), "{e}");
    }
}
