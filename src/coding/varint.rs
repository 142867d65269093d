//! LEB128 unsigned integers: 7 bits a byte, high bit set on all bytes but the last.

/// Appends `value` to `out`.
pub fn put(out: &mut Vec<u8>, mut value: u64) {
    loop {
        let byte = (value & 0x7f) as u8;
        value >>= 7;
        if value == 0 {
            out.push(byte);
            return;
        }
        out.push(byte | 0x80);
    }
}

/// Why a varint could not be read.
#[derive(Debug, PartialEq, Eq)]
pub enum VarintFault {
    /// The bytes end inside the number.
    Truncated,
    /// More than 64 bits of value.
    Overflow,
}

/// Reads a value at `*pos`, advancing it.
pub fn get(bytes: &[u8], pos: &mut usize) -> Result<u64, VarintFault> {
    let mut value = 0u64;
    for shift in (0..64).step_by(7) {
        let byte = *bytes.get(*pos).ok_or(VarintFault::Truncated)?;
        *pos += 1;
        let payload = (byte & 0x7f) as u64;
        if shift == 63 && payload > 1 {
            return Err(VarintFault::Overflow);
        }
        value |= payload << shift;
        if byte & 0x80 == 0 {
            return Ok(value);
        }
    }
    Err(VarintFault::Overflow)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_rejects_cut_and_overlong_numbers() {
        for v in [0, 1, 127, 128, 300, u32::MAX as u64, u64::MAX] {
            let mut out = Vec::new();
            put(&mut out, v);
            let mut pos = 0;
            assert_eq!(get(&out, &mut pos), Ok(v));
            assert_eq!(pos, out.len());
            let mut pos = 0;
            if out.len() > 1 {
                assert_eq!(
                    get(&out[..out.len() - 1], &mut pos),
                    Err(VarintFault::Truncated)
                );
            }
        }
        let mut pos = 0;
        assert_eq!(get(&[0xff; 11], &mut pos), Err(VarintFault::Overflow));
    }
}
