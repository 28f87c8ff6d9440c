//! CDR as ROS 2 serializes messages (OMG XCDR1, little endian, `rmw` / Fast DDS's "plain CDR"): a
//! 4-byte encapsulation header (0x00 0x01 0x00 0x00), then the fields in order, each primitive
//! aligned to its size counted from the end of the header; a string is its length with the
//! terminating NUL (u32), its bytes and the NUL; a sequence its element count (u32), then its
//! elements; a fixed array its elements.

use thiserror::Error;

/// The encapsulation header of little-endian plain CDR.
pub const HEADER_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Why bytes are not a message.
#[derive(Debug, Error, PartialEq)]
pub enum CdrError {
    #[error("{0} bytes are too few for a CDR message")]
    Short(usize),
    #[error("encapsulation {0:#04x}{1:02x} is not little-endian plain CDR")]
    Encapsulation(u8, u8),
    #[error("the message ends at byte {at} inside a {what}")]
    Truncated { at: usize, what: &'static str },
    #[error("a string at byte {0} is not NUL-terminated UTF-8")]
    BadString(usize),
    #[error("a sequence at byte {at} claims {count} elements, more than the {left} bytes left")]
    Length { at: usize, count: usize, left: usize },
}

/// Appends a message's fields to a buffer, aligned as CDR wants.
pub struct CdrWriter<'a> {
    out: &'a mut Vec<u8>,
    /// Where the message's body starts in `out` (alignment counts from there).
    origin: usize,
}

impl<'a> CdrWriter<'a> {
    /// A message appended to `out`: its header first.
    pub fn new(out: &'a mut Vec<u8>) -> Self {
        out.extend_from_slice(&HEADER_LE);
        let origin = out.len();
        Self { out, origin }
    }

    /// Bytes of the body so far.
    pub fn position(&self) -> usize {
        self.out.len() - self.origin
    }

    fn align(&mut self, size: usize) {
        let pad = (size - self.position() % size) % size;
        self.out.extend(std::iter::repeat_n(0u8, pad));
    }

    pub fn bool(&mut self, v: bool) {
        self.out.push(v as u8);
    }

    pub fn u8(&mut self, v: u8) {
        self.out.push(v);
    }

    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    pub fn i64(&mut self, v: i64) {
        self.align(8);
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    pub fn u64(&mut self, v: u64) {
        self.align(8);
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    pub fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.out.extend_from_slice(s.as_bytes());
        self.out.push(0);
    }

    /// A sequence's element count.
    pub fn length(&mut self, n: usize) {
        self.u32(n as u32);
    }

    pub fn f64_sequence(&mut self, values: &[f64]) {
        self.length(values.len());
        if !values.is_empty() {
            self.align(8);
            for v in values {
                self.out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }

    pub fn bytes_sequence(&mut self, values: &[u8]) {
        self.length(values.len());
        self.out.extend_from_slice(values);
    }

    pub fn string_sequence<S: AsRef<str>>(&mut self, values: &[S]) {
        self.length(values.len());
        for s in values {
            self.string(s.as_ref());
        }
    }
}

/// Reads a message's fields in order.
pub struct CdrReader<'a> {
    body: &'a [u8],
    at: usize,
}

impl<'a> CdrReader<'a> {
    /// The message in `bytes`: its header checked.
    pub fn new(bytes: &'a [u8]) -> Result<Self, CdrError> {
        if bytes.len() < 4 {
            return Err(CdrError::Short(bytes.len()));
        }
        if bytes[0] != 0x00 || bytes[1] != 0x01 {
            return Err(CdrError::Encapsulation(bytes[0], bytes[1]));
        }
        Ok(Self { body: &bytes[4..], at: 0 })
    }

    /// Bytes of the body left.
    pub fn remaining(&self) -> usize {
        self.body.len().saturating_sub(self.at)
    }

    fn take(&mut self, size: usize, what: &'static str) -> Result<&'a [u8], CdrError> {
        let pad = (size - self.at % size) % size;
        let start = self.at + pad;
        let end = start + size;
        let slice = self.body.get(start..end).ok_or(CdrError::Truncated { at: self.at + 4, what })?;
        self.at = end;
        Ok(slice)
    }

    pub fn bool(&mut self) -> Result<bool, CdrError> {
        Ok(self.take(1, "bool")?[0] != 0)
    }

    pub fn u8(&mut self) -> Result<u8, CdrError> {
        Ok(self.take(1, "byte")?[0])
    }

    pub fn i32(&mut self) -> Result<i32, CdrError> {
        Ok(i32::from_le_bytes(self.take(4, "int32")?.try_into().unwrap_or_default()))
    }

    pub fn u32(&mut self) -> Result<u32, CdrError> {
        Ok(u32::from_le_bytes(self.take(4, "uint32")?.try_into().unwrap_or_default()))
    }

    pub fn i64(&mut self) -> Result<i64, CdrError> {
        Ok(i64::from_le_bytes(self.take(8, "int64")?.try_into().unwrap_or_default()))
    }

    pub fn u64(&mut self) -> Result<u64, CdrError> {
        Ok(u64::from_le_bytes(self.take(8, "uint64")?.try_into().unwrap_or_default()))
    }

    pub fn f32(&mut self) -> Result<f32, CdrError> {
        Ok(f32::from_le_bytes(self.take(4, "float32")?.try_into().unwrap_or_default()))
    }

    pub fn f64(&mut self) -> Result<f64, CdrError> {
        Ok(f64::from_le_bytes(self.take(8, "float64")?.try_into().unwrap_or_default()))
    }

    /// A sequence's element count, checked against what is left at `min_size` bytes an element.
    pub fn length(&mut self, min_size: usize) -> Result<usize, CdrError> {
        let at = self.at + 4;
        let count = self.u32()? as usize;
        if count.saturating_mul(min_size) > self.remaining() {
            return Err(CdrError::Length { at, count, left: self.remaining() });
        }
        Ok(count)
    }

    pub fn string(&mut self) -> Result<String, CdrError> {
        let at = self.at + 4;
        let len = self.length(1)?;
        if len == 0 {
            // (some writers send an empty string as length 0)
            return Ok(String::new());
        }
        let bytes = self.take_raw(len, "string")?;
        let text = bytes.strip_suffix(&[0]).ok_or(CdrError::BadString(at))?;
        String::from_utf8(text.to_vec()).map_err(|_| CdrError::BadString(at))
    }

    fn take_raw(&mut self, len: usize, what: &'static str) -> Result<&'a [u8], CdrError> {
        let slice = self.body.get(self.at..self.at + len).ok_or(CdrError::Truncated { at: self.at + 4, what })?;
        self.at += len;
        Ok(slice)
    }

    pub fn f64_sequence(&mut self) -> Result<Vec<f64>, CdrError> {
        let n = self.length(8)?;
        (0..n).map(|_| self.f64()).collect()
    }

    pub fn bytes_sequence(&mut self) -> Result<Vec<u8>, CdrError> {
        let n = self.length(1)?;
        Ok(self.take_raw(n, "byte sequence")?.to_vec())
    }

    pub fn string_sequence(&mut self) -> Result<Vec<String>, CdrError> {
        let n = self.length(4)?;
        (0..n).map(|_| self.string()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_align_from_the_end_of_the_header() {
        let mut bytes = Vec::new();
        let mut w = CdrWriter::new(&mut bytes);
        w.u8(7);
        w.f64(1.5);
        w.string("ab");
        w.f64_sequence(&[2.0]);
        // header, the byte, 7 pad bytes to 8, the double, "ab": length 3, 'a' 'b' NUL, then the
        // sequence's count (aligned to 4: one pad byte) and its double (aligned to 8)
        assert_eq!(&bytes[..5], &[0, 1, 0, 0, 7]);
        assert_eq!(&bytes[12..20], &1.5f64.to_le_bytes());
        assert_eq!(&bytes[20..27], &[3, 0, 0, 0, b'a', b'b', 0]);
        assert_eq!(&bytes[28..32], &[1, 0, 0, 0]);
        assert_eq!(&bytes[36..44], &2.0f64.to_le_bytes());
        let mut r = CdrReader::new(&bytes).unwrap();
        assert_eq!((r.u8().unwrap(), r.f64().unwrap(), r.string().unwrap(), r.f64_sequence().unwrap()), (7, 1.5, "ab".to_string(), vec![2.0]));
        assert_eq!(r.remaining(), 0);
    }

    #[test]
    fn bad_bytes_are_errors_not_panics() {
        assert_eq!(CdrReader::new(&[0, 1]).err(), Some(CdrError::Short(2)));
        assert_eq!(CdrReader::new(&[0, 0, 0, 0]).err(), Some(CdrError::Encapsulation(0, 0)));
        let mut r = CdrReader::new(&[0, 1, 0, 0, 200, 0, 0, 0, 1]).unwrap();
        assert!(matches!(r.f64_sequence(), Err(CdrError::Length { count: 200, .. })));
        let mut r = CdrReader::new(&[0, 1, 0, 0, 1, 2]).unwrap();
        assert!(matches!(r.f64(), Err(CdrError::Truncated { .. })));
    }
}
