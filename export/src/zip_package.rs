//! The zip container of fabkit's 3MF packages, written from entries deflated beforehand.
//!
//! A package's model is deflated in independent pieces (each piece a fresh raw deflate stream
//! at level 4, ended by a sync flush so that it closes on a byte boundary, none referring to
//! another's bytes), and the pieces are concatenated and closed by an empty final block: one
//! valid deflate stream (RFC 1951, Sec. 3.2.3-3.2.4), as `pigz` writes it. So a piece is
//! deflated once and written into every package that holds the same text (a part's mesh is
//! the same element in the kit 3MF and on its plate), and the pieces of one large model are
//! deflated in parallel. The bytes depend only on the text and the piece size
//! ([`PIECE_BYTES`]), never on the thread count.
//!
//! Why a writer of our own: the `zip` crate (9) compresses every entry itself (its
//! `PreparedZipFile` cannot be made from data deflated elsewhere), and `rawzip` writes every
//! entry with a trailing data descriptor, which would change the packages' layout for their
//! readers. This writer keeps the layout the `zip` crate gave them: local headers with the
//! CRC-32 and both sizes, no data descriptors and no extra fields, every entry deflated (method
//! 8), dated 1980-01-01 00:00:00 (MS-DOS date 0x0021, time 0), made by Unix (version 2.0) with
//! mode 0644; ZIP64 fields and records only where a size or an offset needs them (PKWARE's
//! APPNOTE.TXT 6.3.10: Sec. 4.3.7 local header, 4.3.12 central directory header, 4.3.14-4.3.16
//! end records, 4.5.3 the ZIP64 extra field).

use crate::ExportError;

/// Bytes of text per independently deflated piece: large enough that a piece's own Huffman
/// tables and lost history cost under 0.1 % of the deflated size, small enough that a 12 MB
/// model is a dozen pieces to share between the cores.
pub(crate) const PIECE_BYTES: usize = 1 << 20;

/// zlib's level for every entry. 4 rather than zlib's default 6: R-Tac0's export took 14 %
/// less CPU (0.81 s against 0.94 s) for 3MF packages 4 % larger (2.39 MB against 2.30 MB;
/// ShadowTac's 7.03 MB against 6.80 MB); level 1 (zlib-rs's quick deflate) made them 64 %
/// larger.
const LEVEL: u32 = 4;

/// Text deflated as one or more independent pieces, not yet closed by a final block: its
/// deflate bytes, the CRC-32 and the length of the text.
#[derive(Debug, Clone)]
pub(crate) struct Deflated {
    data: Vec<u8>,
    crc32: u32,
    len: u64,
}

impl Deflated {
    /// `text` deflated in pieces of [`PIECE_BYTES`], the pieces in parallel.
    ///
    /// # Errors
    /// [`ExportError::ThreeMf`] if the deflater fails (it writes to memory).
    pub(crate) fn of(text: &[u8]) -> Result<Deflated, ExportError> {
        use rayon::prelude::*;
        let pieces: Vec<Vec<u8>> = text
            .par_chunks(PIECE_BYTES)
            .map(deflate_piece)
            .collect::<Result<_, _>>()?;
        Ok(Deflated {
            data: pieces.concat(),
            crc32: crc32fast::hash(text),
            len: text.len() as u64,
        })
    }
}

/// One raw deflate stream of `piece`, ended by a sync flush (an empty stored block: byte
/// aligned, not final). An empty piece gives no bytes.
fn deflate_piece(piece: &[u8]) -> Result<Vec<u8>, ExportError> {
    use flate2::{Compress, Compression, FlushCompress};
    if piece.is_empty() {
        return Ok(Vec::new());
    }
    let mut c = Compress::new(Compression::new(LEVEL), false);
    // Room for the worst case (stored blocks: 5 bytes per 16 KiB, and the flush), so that one
    // call deflates the whole piece.
    let mut out = Vec::with_capacity(piece.len() + piece.len() / 8 + 128);
    loop {
        if out.capacity() - out.len() < 64 {
            out.reserve(out.capacity() / 2 + 64);
        }
        let done = c.total_in() as usize;
        c.compress_vec(&piece[done..], &mut out, FlushCompress::Sync)
            .map_err(|e| ExportError::ThreeMf {
                reason: format!("deflate: {e}"),
            })?;
        // The flush is complete once every byte is in and the output was not filled (zlib's
        // rule for Z_SYNC_FLUSH).
        if c.total_in() as usize == piece.len() && out.len() < out.capacity() {
            return Ok(out);
        }
    }
}

/// The empty final block that closes a stream of pieces: BFINAL = 1, fixed Huffman codes
/// (BTYPE = 01), then the end-of-block code (seven zero bits).
const FINAL_BLOCK: [u8; 2] = [0x03, 0x00];

/// 0xFFFFFFFF: a 32-bit field that says "in the ZIP64 extra field".
const FULL32: u64 = 0xFFFF_FFFF;

/// The zip file of `entries` (name, and the deflated pieces of its data in order), in that
/// order. `force_zip64` writes every ZIP64 field and record even where no size needs it (the
/// tests read such a file back).
///
/// # Errors
/// [`ExportError::ThreeMf`] for more than 65,534 entries or a name longer than 65,535 bytes.
pub(crate) fn package(
    entries: &[(&str, Vec<&Deflated>)],
    force_zip64: bool,
) -> Result<Vec<u8>, ExportError> {
    let refuse = |reason: String| Err(ExportError::ThreeMf { reason });
    if entries.len() >= 0xFFFF {
        return refuse(format!("{} zip entries (at most 65,534)", entries.len()));
    }
    let total: usize = entries
        .iter()
        .map(|(n, d)| 128 + 2 * n.len() + d.iter().map(|p| p.data.len()).sum::<usize>())
        .sum();
    let mut out: Vec<u8> = Vec::with_capacity(total + 128);
    let mut central: Vec<u8> = Vec::new();
    for (name, pieces) in entries {
        if name.len() > 0xFFFF {
            return refuse(format!("zip entry name of {} bytes", name.len()));
        }
        let mut crc = crc32fast::Hasher::new();
        let mut len = 0u64;
        let mut deflated = FINAL_BLOCK.len() as u64;
        for p in pieces {
            crc.combine(&crc32fast::Hasher::new_with_initial_len(p.crc32, p.len));
            len += p.len;
            deflated += p.data.len() as u64;
        }
        let crc = crc.finalize();
        let offset = out.len() as u64;
        let sizes64 = force_zip64 || len >= FULL32 || deflated >= FULL32;
        let offset64 = force_zip64 || offset >= FULL32;
        // local file header
        put32(&mut out, 0x0403_4b50);
        put16(&mut out, if sizes64 { 45 } else { 20 });
        put16(&mut out, 0); // flags
        put16(&mut out, 8); // deflated
        put16(&mut out, 0); // 00:00:00
        put16(&mut out, 0x0021); // 1980-01-01
        put32(&mut out, crc);
        if sizes64 {
            put32(&mut out, FULL32 as u32);
            put32(&mut out, FULL32 as u32);
        } else {
            put32(&mut out, deflated as u32);
            put32(&mut out, len as u32);
        }
        put16(&mut out, name.len() as u16);
        put16(&mut out, if sizes64 { 20 } else { 0 });
        out.extend_from_slice(name.as_bytes());
        if sizes64 {
            put16(&mut out, 0x0001);
            put16(&mut out, 16);
            put64(&mut out, len);
            put64(&mut out, deflated);
        }
        for p in pieces {
            out.extend_from_slice(&p.data);
        }
        out.extend_from_slice(&FINAL_BLOCK);
        // its central directory header: the ZIP64 extra field holds, in this order, the
        // fields that say FULL32
        let mut extra = Vec::new();
        if sizes64 {
            put64(&mut extra, len);
            put64(&mut extra, deflated);
        }
        if offset64 {
            put64(&mut extra, offset);
        }
        let zip64 = sizes64 || offset64;
        put32(&mut central, 0x0201_4b50);
        put16(&mut central, 0x0300 | if zip64 { 45 } else { 20 }); // made by Unix
        put16(&mut central, if zip64 { 45 } else { 20 });
        put16(&mut central, 0);
        put16(&mut central, 8);
        put16(&mut central, 0);
        put16(&mut central, 0x0021);
        put32(&mut central, crc);
        for (v, big) in [(deflated, sizes64), (len, sizes64)] {
            put32(&mut central, if big { FULL32 as u32 } else { v as u32 });
        }
        put16(&mut central, name.len() as u16);
        put16(&mut central, if zip64 { extra.len() as u16 + 4 } else { 0 });
        put16(&mut central, 0); // comment
        put16(&mut central, 0); // disk
        put16(&mut central, 0); // internal attributes
        put32(&mut central, 0o100_644 << 16); // regular file, rw-r--r--
        put32(
            &mut central,
            if offset64 {
                FULL32 as u32
            } else {
                offset as u32
            },
        );
        central.extend_from_slice(name.as_bytes());
        if zip64 {
            put16(&mut central, 0x0001);
            put16(&mut central, extra.len() as u16);
            central.extend_from_slice(&extra);
        }
    }
    let cd_offset = out.len() as u64;
    let cd_size = central.len() as u64;
    out.extend_from_slice(&central);
    let n = entries.len() as u64;
    let end64 = force_zip64 || cd_offset >= FULL32 || cd_size >= FULL32;
    if end64 {
        // ZIP64 end of central directory record and its locator
        let record = out.len() as u64;
        put32(&mut out, 0x0606_4b50);
        put64(&mut out, 44);
        put16(&mut out, 0x0300 | 45);
        put16(&mut out, 45);
        put32(&mut out, 0);
        put32(&mut out, 0);
        put64(&mut out, n);
        put64(&mut out, n);
        put64(&mut out, cd_size);
        put64(&mut out, cd_offset);
        put32(&mut out, 0x0706_4b50);
        put32(&mut out, 0);
        put64(&mut out, record);
        put32(&mut out, 1);
    }
    put32(&mut out, 0x0605_4b50);
    put16(&mut out, 0);
    put16(&mut out, 0);
    put16(&mut out, n as u16);
    put16(&mut out, n as u16);
    let clamp = |v: u64| if end64 { FULL32 as u32 } else { v as u32 };
    put32(&mut out, clamp(cd_size));
    put32(&mut out, clamp(cd_offset));
    put16(&mut out, 0); // comment
    Ok(out)
}

fn put16(out: &mut Vec<u8>, v: u16) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    /// Text that deflates to about a fifth, like a mesh's XML, `n` bytes.
    fn text(n: usize) -> Vec<u8> {
        let mut s = String::new();
        let mut i = 0u64;
        while s.len() < n {
            i += 1;
            let x = (i * 2_654_435_761) % 100_003;
            s.push_str(&format!(
                "     <vertex x=\"{}.{}\" y=\"{}\"/>\n",
                x / 7,
                x % 97,
                i
            ));
        }
        s.truncate(n);
        s.into_bytes()
    }

    fn read_back(zip: &[u8]) -> Vec<(String, Vec<u8>)> {
        let mut a = zip::ZipArchive::new(std::io::Cursor::new(zip)).expect("a zip file");
        (0..a.len())
            .map(|i| {
                let mut f = a.by_index(i).unwrap();
                assert_eq!(f.compression(), zip::CompressionMethod::Deflated);
                let mut v = Vec::new();
                f.read_to_end(&mut v).expect("inflates, CRC-32 checked");
                (f.name().unwrap().to_string(), v)
            })
            .collect()
    }

    /// Pieces deflated apart and shared between entries inflate to their texts, in entries
    /// with and without ZIP64 fields; the bytes are the same on one thread and on several.
    #[test]
    fn shared_pieces_inflate_to_the_entries_texts() {
        let big = text(2 * PIECE_BYTES + 12_345);
        let small = b"<model>\n".to_vec();
        let empty: Vec<u8> = Vec::new();
        let [d_big, d_small, d_empty] = [&big, &small, &empty].map(|t| Deflated::of(t).unwrap());
        assert!(
            d_big.data.len() * 3 < big.len(),
            "deflated to under a third"
        );
        for force in [false, true] {
            let zip = package(
                &[
                    ("a.xml", vec![&d_small, &d_big, &d_small]),
                    ("b/empty", vec![&d_empty]),
                    ("c.xml", vec![&d_big]),
                    ("d", vec![]),
                ],
                force,
            )
            .unwrap();
            let back = read_back(&zip);
            let a: Vec<u8> = [&small[..], &big, &small].concat();
            assert_eq!(back.len(), 4);
            assert_eq!((back[0].0.as_str(), &back[0].1), ("a.xml", &a));
            assert_eq!((back[1].0.as_str(), &back[1].1), ("b/empty", &empty));
            assert_eq!((back[2].0.as_str(), &back[2].1), ("c.xml", &big));
            assert_eq!((back[3].0.as_str(), &back[3].1), ("d", &empty));
            // the ZIP64 end records are there exactly when forced
            assert_eq!(zip.windows(4).any(|w| w == [0x50, 0x4b, 6, 6]), force);
        }
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| Deflated::of(&big).unwrap());
        assert_eq!(one.data, d_big.data);
    }

    /// The layout the packages had from the `zip` crate: a plain entry's local header holds
    /// the CRC-32 and both sizes, no extra field, Unix mode 0644 in the central directory.
    #[test]
    fn a_plain_entry_has_its_sizes_in_its_local_header() {
        let d = Deflated::of(b"hello hello hello").unwrap();
        let zip = package(&[("x", vec![&d])], false).unwrap();
        assert_eq!(&zip[0..4], &[0x50, 0x4b, 3, 4]);
        let u32_at = |i: usize| u32::from_le_bytes(zip[i..i + 4].try_into().unwrap());
        assert_eq!(u32_at(14), crc32fast::hash(b"hello hello hello"));
        assert_eq!(u32_at(18) as usize, d.data.len() + 2);
        assert_eq!(u32_at(22), 17);
        assert_eq!(&zip[28..30], &[0, 0], "no extra field");
        let mut a = zip::ZipArchive::new(std::io::Cursor::new(&zip)).unwrap();
        assert_eq!(a.by_index(0).unwrap().unix_mode(), Some(0o100_644));
    }
}
