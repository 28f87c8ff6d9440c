//! PNG charts and heatmaps with labels, drawn without any font files (a built-in 3×5 pixel font):
//! the envelope's heatmap (`diagnose`) and the sizing charts (`sizing`) both draw here.

use std::path::Path;

const FONT: &[(char, [&str; 5])] = &[
    ('0', ["111", "101", "101", "101", "111"]), ('1', ["010", "110", "010", "010", "111"]), ('2', ["111", "001", "111", "100", "111"]),
    ('3', ["111", "001", "111", "001", "111"]), ('4', ["101", "101", "111", "001", "001"]), ('5', ["111", "100", "111", "001", "111"]),
    ('6', ["111", "100", "111", "101", "111"]), ('7', ["111", "001", "001", "001", "001"]), ('8', ["111", "101", "111", "101", "111"]),
    ('9', ["111", "101", "111", "001", "111"]), ('.', ["000", "000", "000", "000", "010"]), ('-', ["000", "000", "111", "000", "000"]),
    ('/', ["001", "001", "010", "100", "100"]), ('(', ["010", "100", "100", "100", "010"]), (')', ["010", "001", "001", "001", "010"]),
    ('=', ["000", "111", "000", "111", "000"]), ('>', ["100", "010", "001", "010", "100"]), (',', ["000", "000", "000", "010", "100"]),
    ('A', ["010", "101", "111", "101", "101"]), ('B', ["110", "101", "110", "101", "110"]), ('C', ["011", "100", "100", "100", "011"]),
    ('D', ["110", "101", "101", "101", "110"]), ('E', ["111", "100", "110", "100", "111"]), ('F', ["111", "100", "110", "100", "100"]),
    ('G', ["011", "100", "101", "101", "011"]), ('H', ["101", "101", "111", "101", "101"]), ('I', ["111", "010", "010", "010", "111"]),
    ('J', ["001", "001", "001", "101", "010"]), ('K', ["101", "101", "110", "101", "101"]), ('L', ["100", "100", "100", "100", "111"]),
    ('M', ["101", "111", "111", "101", "101"]), ('N', ["110", "101", "101", "101", "101"]), ('O', ["010", "101", "101", "101", "010"]),
    ('P', ["110", "101", "110", "100", "100"]), ('Q', ["010", "101", "101", "110", "011"]), ('R', ["110", "101", "110", "101", "101"]),
    ('S', ["011", "100", "010", "001", "110"]), ('T', ["111", "010", "010", "010", "010"]), ('U', ["101", "101", "101", "101", "111"]),
    ('V', ["101", "101", "101", "101", "010"]), ('W', ["101", "101", "111", "111", "101"]), ('X', ["101", "101", "010", "101", "101"]),
    ('Y', ["101", "101", "010", "010", "010"]), ('Z', ["111", "001", "010", "100", "111"]),
];

pub struct Canvas {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
}

impl Canvas {
    pub fn new(width: usize, height: usize, background: [u8; 3]) -> Self {
        Self { width, height, rgb: background.iter().copied().cycle().take(width * height * 3).collect() }
    }

    pub fn fill(&mut self, x0: usize, y0: usize, w: usize, h: usize, c: [u8; 3]) {
        for y in y0..(y0 + h).min(self.height) {
            for x in x0..(x0 + w).min(self.width) {
                let i = 3 * (y * self.width + x);
                self.rgb[i..i + 3].copy_from_slice(&c);
            }
        }
    }

    /// Text in capitals at (x, y), `scale` pixels per font pixel ([`Self::text_width`] wide).
    pub fn text(&mut self, x: usize, y: usize, text: &str, scale: usize, c: [u8; 3]) {
        let mut cx = x;
        for ch in text.to_uppercase().chars() {
            if let Some((_, rows)) = FONT.iter().find(|(g, _)| *g == ch) {
                for (r, row) in rows.iter().enumerate() {
                    for (col, bit) in row.chars().enumerate() {
                        if bit == '1' {
                            self.fill(cx + col * scale, y + r * scale, scale, scale, c);
                        }
                    }
                }
            }
            cx += 4 * scale;
        }
    }

    pub fn text_width(text: &str, scale: usize) -> usize {
        text.chars().count() * 4 * scale
    }

    pub fn save_png(&self, path: &Path) -> Result<(), String> {
        let file = std::fs::File::create(path).map_err(|e| e.to_string())?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), self.width as u32, self.height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&self.rgb).map_err(|e| e.to_string())
    }
}

/// Blue (low) → green → yellow (at 1) → red (above): for need/limit ratios.
pub fn ratio_color(ratio: f64) -> [u8; 3] {
    if ratio > 1.0 {
        let t = ((ratio.log2()) / 2.0).clamp(0.0, 1.0);
        return [(230.0 - 60.0 * t) as u8, (60.0 - 40.0 * t) as u8, (50.0 - 20.0 * t) as u8];
    }
    let t = ((ratio.max(1e-3).log2() + 5.0) / 5.0).clamp(0.0, 1.0); // 1/32 .. 1
    let stops = [[40.0, 60.0, 140.0], [40.0, 140.0, 140.0], [90.0, 180.0, 80.0], [240.0, 220.0, 60.0]];
    let x = t * 3.0;
    let i = (x.floor() as usize).min(2);
    let f = x - i as f64;
    let mix = |a: f64, b: f64| (a + f * (b - a)) as u8;
    [mix(stops[i][0], stops[i + 1][0]), mix(stops[i][1], stops[i + 1][1]), mix(stops[i][2], stops[i + 1][2])]
}

/// A labelled heatmap: `values[row][col]` (rows bottom to top), each cell printing its value.
pub fn heatmap(title: &str, x_label: &str, x_ticks: &[String], y_label: &str, y_ticks: &[String], values: &[Vec<f64>]) -> Canvas {
    let (cw, ch) = (64, 40);
    let (left, bottom, top, right) = (110, 80, 60, 30);
    let (cols, rows) = (x_ticks.len(), y_ticks.len());
    let mut c = Canvas::new(left + cols * cw + right, top + rows * ch + bottom, [250, 250, 250]);
    let dark = [30, 30, 30];
    c.text(left, 18, title, 3, dark);
    for (r, row) in values.iter().enumerate() {
        let y = top + (rows - 1 - r) * ch;
        for (col, &v) in row.iter().enumerate() {
            let x = left + col * cw;
            let fill = ratio_color(v);
            c.fill(x, y, cw - 2, ch - 2, fill);
            let label = if v >= 10.0 { format!("{v:.0}") } else { format!("{v:.2}") };
            let luminance = 0.3 * fill[0] as f64 + 0.59 * fill[1] as f64 + 0.11 * fill[2] as f64;
            let ink = if luminance < 120.0 { [255, 255, 255] } else { dark };
            c.text(x + (cw - 2 - Canvas::text_width(&label, 2)) / 2, y + ch / 2 - 5, &label, 2, ink);
        }
        c.text(left - 12 - Canvas::text_width(&y_ticks[r], 2), y + ch / 2 - 5, &y_ticks[r], 2, dark);
    }
    for (col, tick) in x_ticks.iter().enumerate() {
        c.text(left + col * cw + (cw - Canvas::text_width(tick, 2)) / 2, top + rows * ch + 8, tick, 2, dark);
    }
    c.text(left + (cols * cw - Canvas::text_width(x_label, 2)) / 2, top + rows * ch + 40, x_label, 2, dark);
    c.text(8, top - 22, y_label, 2, dark);
    c
}
