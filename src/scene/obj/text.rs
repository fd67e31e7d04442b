//! Reading an OBJ or MTL file as text: capped in size, checked for encodings and binary data,
//! with the small helpers the error messages share.

use std::path::Path;

use super::MAX_FILE_BYTES;

/// Reads a whole OBJ/MTL file as UTF-8 text; the error says what is wrong (no path).
pub(super) fn read_text(path: &Path) -> std::result::Result<String, String> {
    // A regular file (a device would be read forever, a FIFO blocks), read with the cap
    // counted as the bytes arrive.
    let bytes = crate::files::read_capped(path, MAX_FILE_BYTES, "mesh or material file")?;
    decode_text(bytes)
}

/// Checks that `bytes` are UTF-8 text (not empty, not UTF-16, no NUL) and strips a UTF-8 BOM.
fn decode_text(bytes: Vec<u8>) -> std::result::Result<String, String> {
    if bytes.is_empty() {
        return Err("file is empty (0 bytes)".into());
    }
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(
            "text is UTF-16 encoded (it starts with a UTF-16 byte-order mark); save it as UTF-8"
                .into(),
        );
    }
    if let Some(offset) = bytes.iter().position(|&b| b == 0) {
        if looks_like_utf16(&bytes) {
            return Err(
                "text looks UTF-16 encoded (every other byte is NUL); save it as UTF-8".into(),
            );
        }
        let like = binary_kind(&bytes).map_or(String::new(), |k| format!(", it starts like {k}"));
        return Err(format!(
            "line {}: binary data (NUL byte at offset {offset}{like}); not a text file",
            line_of(&bytes, offset)
        ));
    }
    let mut text = String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        format!(
            "line {}: not UTF-8 text (invalid byte 0x{:02X} at offset {offset}); save it as UTF-8",
            line_of(bytes, offset),
            bytes.get(offset).copied().unwrap_or(0)
        )
    })?;
    // A UTF-8 byte-order mark would glue itself to the first keyword ("\u{feff}v"), which tobj
    // would then skip as unknown, silently losing the first vertex.
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// True when the start reads as UTF-16 text without a BOM: in nine pairs of bytes out of ten,
/// one byte (the same one in every pair) is NUL and the other printable ASCII or whitespace.
/// Binary files have NULs too (an executable's header is mostly zeros), but not in that
/// pattern.
fn looks_like_utf16(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(512)];
    let pairs = head.len() / 2;
    if pairs < 2 {
        return false;
    }
    let text = |b: u8| matches!(b, b'\t' | b'\n' | b'\r' | 0x20..=0x7e);
    [0, 1].into_iter().any(|nul| {
        let texty = head
            .chunks_exact(2)
            .filter(|pair| pair[nul] == 0 && text(pair[1 - nul]))
            .count();
        texty * 10 >= pairs * 9
    })
}

/// What a binary file looks like from its first bytes, for the error message.
fn binary_kind(bytes: &[u8]) -> Option<&'static str> {
    const MAGIC: &[(&[u8], &str)] = &[
        (b"\x7fELF", "an ELF executable or library"),
        (b"MZ", "a Windows executable"),
        (b"\x89PNG", "a PNG image"),
        (b"\xff\xd8\xff", "a JPEG image"),
        (b"PK\x03\x04", "a ZIP archive"),
        (b"\x1f\x8b", "a gzip archive"),
        (b"glTF", "a binary glTF file"),
    ];
    MAGIC
        .iter()
        .find(|(magic, _)| bytes.starts_with(magic))
        .map(|&(_, kind)| kind)
}

/// 1-based line number of byte `offset`.
fn line_of(bytes: &[u8], offset: usize) -> usize {
    bytes[..offset.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// A token shortened for an error message.
pub(super) fn quote(token: &str) -> String {
    const MAX: usize = 40;
    match token.char_indices().nth(MAX) {
        Some((cut, _)) => format!("'{}...'", &token[..cut]),
        None => format!("'{token}'"),
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_encodings_and_binary() {
        assert!(decode_text(vec![]).unwrap_err().contains("empty"));
        let utf16: Vec<u8> = "v 1 2 3\n"
            .encode_utf16()
            .flat_map(|u| u.to_le_bytes())
            .collect();
        assert!(decode_text(utf16.clone()).unwrap_err().contains("UTF-16"));
        let mut bom = vec![0xFF, 0xFE];
        bom.extend(utf16);
        assert!(decode_text(bom).unwrap_err().contains("UTF-16"));
        assert!(decode_text(b"v 1\n\x00\x01\x02".to_vec())
            .unwrap_err()
            .contains("line 2: binary"));
        assert!(decode_text(b"v 1 2 3\nv \xe9 1 2\n".to_vec())
            .unwrap_err()
            .contains("line 2: not UTF-8"));
        assert_eq!(decode_text(b"\xEF\xBB\xBFv".to_vec()).unwrap(), "v");
    }
}
