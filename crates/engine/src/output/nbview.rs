//! Trajectories in the NBView format of the LJ-box assignment, read by its viewer.
//!
//! Binary (`NBView01`): the ASCII tag `NBView01`, a line feed, then the header — particle count
//! as a big-endian u32 and the view-box scale as a big-endian IEEE-754 f32 — then frames
//! back to back, each `n` pairs of big-endian f32 (x, y) in particle-id order, with no markers.
//!
//! Text (`NBView00`): the tag `NBView00` and a line feed, a line `n scale`, then per frame `n`
//! lines `x y` (shortest round-trip decimal form), with no markers.
//!
//! 3-D scenarios are written as their (x, y) projection.

use std::io::{self, Read, Write};

/// Which NBView encoding a trajectory is written in (`run --format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum NbviewFormat {
    /// `NBView00`: text.
    NbviewText,
    /// `NBView01`: big-endian binary.
    NbviewBin,
}

pub(crate) const TEXT_TAG: &[u8; 8] = b"NBView00";
pub(crate) const BINARY_TAG: &[u8; 8] = b"NBView01";

/// Writes the tag and header.
pub(crate) fn write_header(
    out: &mut impl Write,
    format: NbviewFormat,
    n: u32,
    scale: f32,
) -> io::Result<()> {
    match format {
        NbviewFormat::NbviewBin => {
            out.write_all(BINARY_TAG)?;
            out.write_all(b"\n")?;
            out.write_all(&n.to_be_bytes())?;
            out.write_all(&scale.to_be_bytes())
        }
        NbviewFormat::NbviewText => {
            out.write_all(TEXT_TAG)?;
            writeln!(out)?;
            writeln!(out, "{n} {scale}")
        }
    }
}

/// Writes one frame of (x, y) pairs.
pub(crate) fn write_frame(
    out: &mut impl Write,
    format: NbviewFormat,
    xy: &[[f32; 2]],
) -> io::Result<()> {
    for p in xy {
        match format {
            NbviewFormat::NbviewBin => {
                out.write_all(&p[0].to_be_bytes())?;
                out.write_all(&p[1].to_be_bytes())?;
            }
            NbviewFormat::NbviewText => writeln!(out, "{} {}", p[0], p[1])?,
        }
    }
    Ok(())
}

/// A binary trajectory read back: header and frames.
#[derive(Debug, PartialEq)]
pub struct Trajectory {
    /// Particles per frame.
    pub n: u32,
    /// Side of the view box [0, scale]²: the box side, or the initial extent of an open system.
    pub scale: f32,
    /// Each frame's (x, y) positions, in particle-id order.
    pub frames: Vec<Vec<[f32; 2]>>,
}

/// Reads a binary (`NBView01`) trajectory; errors on a wrong tag or a truncated frame.
pub fn read_binary(mut input: impl Read) -> io::Result<Trajectory> {
    let bad = |msg: &str| io::Error::new(io::ErrorKind::InvalidData, msg.to_string());
    let mut tag = [0u8; 9];
    input.read_exact(&mut tag)?;
    if &tag[..8] != BINARY_TAG || tag[8] != b'\n' {
        return Err(bad("not an NBView01 file (tag missing)"));
    }
    let mut word = [0u8; 4];
    input.read_exact(&mut word)?;
    let n = u32::from_be_bytes(word);
    input.read_exact(&mut word)?;
    let scale = f32::from_be_bytes(word);
    let mut rest = Vec::new();
    input.read_to_end(&mut rest)?;
    let frame_bytes = n as usize * 8;
    if frame_bytes == 0 || rest.len() % frame_bytes != 0 {
        return Err(bad(
            "truncated NBView01 file: data is not a whole number of frames",
        ));
    }
    let f = |b: &[u8]| f32::from_be_bytes(b.try_into().expect("4 bytes"));
    let frames = rest
        .chunks_exact(frame_bytes)
        .map(|fr| {
            fr.chunks_exact(8)
                .map(|p| [f(&p[..4]), f(&p[4..])])
                .collect()
        })
        .collect();
    Ok(Trajectory { n, scale, frames })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binary_layout_is_as_documented() {
        let mut buf = Vec::new();
        write_header(&mut buf, NbviewFormat::NbviewBin, 2, 1.0).unwrap();
        write_frame(
            &mut buf,
            NbviewFormat::NbviewBin,
            &[[0.5, -2.0], [1.0, 0.25]],
        )
        .unwrap();
        let expected: Vec<u8> = [
            b"NBView01\n".to_vec(),
            vec![0, 0, 0, 2],       // n = 2, big-endian
            vec![0x3f, 0x80, 0, 0], // 1.0f32
            vec![0x3f, 0, 0, 0],    // 0.5
            vec![0xc0, 0, 0, 0],    // -2.0
            vec![0x3f, 0x80, 0, 0], // 1.0
            vec![0x3e, 0x80, 0, 0], // 0.25
        ]
        .concat();
        assert_eq!(buf, expected);
    }

    #[test]
    fn binary_round_trips() {
        let frames = vec![
            vec![[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]],
            vec![[1.1, 1.2], [1.3, 1.4], [1.5, 1.6]],
        ];
        let mut buf = Vec::new();
        write_header(&mut buf, NbviewFormat::NbviewBin, 3, 2.5).unwrap();
        for f in &frames {
            write_frame(&mut buf, NbviewFormat::NbviewBin, f).unwrap();
        }
        let t = read_binary(&buf[..]).unwrap();
        assert_eq!(
            t,
            Trajectory {
                n: 3,
                scale: 2.5,
                frames
            }
        );
        // A truncated file is refused, not half-read.
        assert!(read_binary(&buf[..buf.len() - 3]).is_err());
        assert!(read_binary(&b"NBView00\n"[..]).is_err());
    }

    #[test]
    fn text_format() {
        let mut buf = Vec::new();
        write_header(&mut buf, NbviewFormat::NbviewText, 1, 1.0).unwrap();
        write_frame(&mut buf, NbviewFormat::NbviewText, &[[0.5, 0.1]]).unwrap();
        assert_eq!(String::from_utf8(buf).unwrap(), "NBView00\n1 1\n0.5 0.1\n");
    }
}
