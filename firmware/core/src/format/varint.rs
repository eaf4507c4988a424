//! LEB128 variable-length integers with zigzag for signed values.
//!
//! Hand-written: the few crates for this are std-only or bring an API for
//! `io::Read`; these are a dozen lines over a byte slice, in no_std.

/// Longest encoding of a `u64`.
pub const MAX_LEN: usize = 10;

/// Writes `value` at the start of `out`; returns the bytes used, or `None`
/// if `out` is too short.
pub fn write_u64(mut value: u64, out: &mut [u8]) -> Option<usize> {
    let mut i = 0;
    loop {
        let byte = (value & 0x7f) as u8;
        value >>= 7;
        let slot = out.get_mut(i)?;
        i += 1;
        if value == 0 {
            *slot = byte;
            return Some(i);
        }
        *slot = byte | 0x80;
    }
}

/// Reads a `u64` from the start of `bytes`; returns it and the bytes used,
/// or `None` if the encoding is truncated or longer than a `u64`.
#[inline]
pub fn read_u64(bytes: &[u8]) -> Option<(u64, usize)> {
    // One byte (a frame's time step, on the host millions of times) without
    // the loop.
    match bytes.first() {
        Some(&byte) if byte & 0x80 == 0 => Some((u64::from(byte), 1)),
        _ => read_long(bytes),
    }
}

fn read_long(bytes: &[u8]) -> Option<(u64, usize)> {
    let mut value = 0u64;
    for (i, &byte) in bytes.iter().enumerate().take(MAX_LEN) {
        let bits = u64::from(byte & 0x7f);
        let shift = 7 * i as u32;
        // The tenth byte may only carry the top bit of a u64.
        if i == MAX_LEN - 1 && bits > 1 {
            return None;
        }
        value |= bits << shift;
        if byte & 0x80 == 0 {
            return Some((value, i + 1));
        }
    }
    None
}

/// Zigzag mapping: small magnitudes of either sign become small unsigned values.
#[must_use]
pub const fn zigzag(value: i64) -> u64 {
    ((value << 1) ^ (value >> 63)) as u64
}

/// Inverse of [`zigzag`].
#[must_use]
pub const fn unzigzag(value: u64) -> i64 {
    ((value >> 1) as i64) ^ -((value & 1) as i64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn unsigned_round_trip(v in any::<u64>()) {
            let mut buf = [0u8; MAX_LEN];
            let n = write_u64(v, &mut buf).unwrap();
            prop_assert_eq!(read_u64(&buf[..n]), Some((v, n)));
            prop_assert_eq!(read_u64(&buf[..n - 1]), None);
        }

        #[test]
        fn signed_round_trip(v in any::<i64>()) {
            prop_assert_eq!(unzigzag(zigzag(v)), v);
        }

        #[test]
        fn never_panics_on_garbage(bytes in proptest::collection::vec(any::<u8>(), 0..16)) {
            let _ = read_u64(&bytes);
        }
    }

    #[test]
    fn frame_interval_takes_two_bytes() {
        let mut buf = [0u8; MAX_LEN];
        assert_eq!(write_u64(10_000, &mut buf), Some(2));
        assert_eq!(zigzag(-1), 1);
        assert_eq!(zigzag(1), 2);
    }
}
