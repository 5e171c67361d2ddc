//! Siemens CSA headers (the private elements (0029,1010) and (0029,1020), "SV10" format), read
//! only as far as mosaics need: `NumberOfImagesInMosaic` and `SliceNormalVector`. The layout is
//! nibabel's `csareader` documents it: "SV10", four unused bytes, the tag count, 77, then per
//! tag a 64-byte name, VM, a 4-byte VR, the SyngoDT, the item count and 77 or 205, then per item
//! four 32-bit lengths and the value padded to 4 bytes. Bounded by the bytes given: a lying
//! count or length ends the walk, never an allocation.

/// The values of tag `name` in CSA header `bytes`, as the strings it stores (trimmed); `None`
/// where the header is not SV10 or has no such tag with values.
pub fn values(bytes: &[u8], name: &str) -> Option<Vec<String>> {
    let u32_at = |at: usize| -> Option<u32> {
        Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
    };
    if !bytes.starts_with(b"SV10") {
        return None;
    }
    let tags = u32_at(8)?;
    let mut at = 16usize;
    for _ in 0..tags.min(1024) {
        let tag_name = bytes.get(at..at + 64)?;
        let end = tag_name.iter().position(|&b| b == 0).unwrap_or(64);
        let this = std::str::from_utf8(&tag_name[..end]).ok()?;
        let items = u32_at(at + 76)?;
        at += 84;
        let mut found = Vec::new();
        for _ in 0..items.min(1024) {
            let len = u32_at(at + 4)? as usize;
            at += 16;
            let value = bytes.get(at..at.checked_add(len)?)?;
            let text = String::from_utf8_lossy(value);
            let text = text.trim_matches(|c: char| c == '\0' || c.is_whitespace());
            if !text.is_empty() {
                found.push(text.to_string());
            }
            at = at.checked_add(len.div_ceil(4) * 4)?;
        }
        if this == name {
            return (!found.is_empty()).then_some(found);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An SV10 header of `tags` (name, values).
    fn header(tags: &[(&str, &[&str])]) -> Vec<u8> {
        let mut b = b"SV10\x04\x03\x02\x01".to_vec();
        b.extend((tags.len() as u32).to_le_bytes());
        b.extend(77u32.to_le_bytes());
        for (name, values) in tags {
            let mut n = name.as_bytes().to_vec();
            n.resize(64, 0);
            b.extend(n);
            b.extend(1i32.to_le_bytes());
            b.extend(b"DS\0\0");
            b.extend(3i32.to_le_bytes());
            b.extend((values.len() as u32).to_le_bytes());
            b.extend(77u32.to_le_bytes());
            for v in *values {
                let mut bytes = v.as_bytes().to_vec();
                bytes.push(0);
                let len = bytes.len() as u32;
                for _ in 0..4 {
                    b.extend(len.to_le_bytes());
                }
                bytes.resize(bytes.len().div_ceil(4) * 4, 0);
                b.extend(bytes);
            }
        }
        b
    }

    #[test]
    fn tags_are_found_past_others_and_lies_end_the_walk() {
        let h = header(&[
            ("EchoLinePosition", &["64"]),
            ("SliceNormalVector", &["0.0", "-0.0087", "0.99996"]),
            ("NumberOfImagesInMosaic", &["48"]),
        ]);
        assert_eq!(
            values(&h, "NumberOfImagesInMosaic"),
            Some(vec!["48".to_string()])
        );
        assert_eq!(values(&h, "SliceNormalVector").map(|v| v.len()), Some(3));
        assert_eq!(values(&h, "Missing"), None);
        assert_eq!(values(b"SV1", "Any"), None);
        // A length past the end: no value, no panic.
        let mut cut = h.clone();
        cut.truncate(h.len() - 8);
        assert_eq!(values(&cut, "NumberOfImagesInMosaic"), None);
        let mut lying = h;
        lying[16 + 84 + 4..16 + 84 + 8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(values(&lying, "NumberOfImagesInMosaic"), None);
    }
}
