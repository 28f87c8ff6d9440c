//! NumPy `.npy` files of float64 (format version 1.0, C order), for joint schedules.

/// Write a 2-D float64 array.
pub fn write_f64(rows: usize, cols: usize, data: &[f64]) -> Vec<u8> {
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    // magic (6) + version (2) + length (2) + header + '\n' must be a multiple of 64
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 8 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for x in data {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

/// Read a float64 array: its shape and its values in C order.
pub fn read_f64(bytes: &[u8]) -> Result<(Vec<usize>, Vec<f64>), String> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err("not an .npy file".into());
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
        v => return Err(format!("unsupported .npy version {v}")),
    };
    let header = std::str::from_utf8(bytes.get(start..start + len).ok_or("truncated header")?).map_err(|_| "header is not text")?;
    if !header.contains("'<f8'") {
        return Err("only little-endian float64 ('<f8') arrays are supported".into());
    }
    if header.contains("'fortran_order': True") {
        return Err("Fortran-ordered arrays are not supported".into());
    }
    let shape_text = header.split("'shape':").nth(1).and_then(|s| s.split('(').nth(1)).and_then(|s| s.split(')').next()).ok_or("no shape in header")?;
    let shape: Vec<usize> = shape_text.split(',').map(str::trim).filter(|s| !s.is_empty()).map(|s| s.parse().map_err(|_| format!("bad shape '{shape_text}'"))).collect::<Result<_, _>>()?;
    let count: usize = shape.iter().product();
    let body = &bytes[start + len..];
    if body.len() != 8 * count {
        return Err(format!("expected {count} values, found {} bytes", body.len()));
    }
    Ok((shape, body.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()))
}

#[cfg(test)]
mod tests {
    #[test]
    fn round_trip() {
        let data: Vec<f64> = (0..12).map(|i| i as f64 * 0.25 - 1.0).collect();
        let bytes = super::write_f64(4, 3, &data);
        assert_eq!((bytes.len() - 8 * 12) % 64, 0, "header aligned to 64 bytes");
        assert_eq!(super::read_f64(&bytes).unwrap(), (vec![4, 3], data));
        assert!(super::read_f64(b"junk").is_err());
    }
}
