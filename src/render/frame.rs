//! A rendered image read back from the GPU: RGBA8 colour and window-space
//! depth, both stored top row first (as image files are, unlike GL).

use std::path::Path;

use crate::error::{Error, Result};

/// Colour and depth of one rendered frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes, RGBA, row 0 at the top.
    pub rgba: Vec<u8>,
    /// `width * height` window-space depths in [0, 1] (1 = background,
    /// nothing drawn), row 0 at the top. With MSAA it is one sample's depth.
    pub depth: Vec<f32>,
}

impl Frame {
    /// The RGBA colour at column `x`, row `y` (row 0 at the top); `None` outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = 4 * (y as usize * self.width as usize + x as usize);
        self.rgba.get(i..i + 4)?.try_into().ok()
    }

    /// The depth at column `x`, row `y` (row 0 at the top); `None` outside the image.
    pub fn depth_at(&self, x: u32, y: u32) -> Option<f32> {
        if x >= self.width || y >= self.height {
            return None;
        }
        self.depth
            .get(y as usize * self.width as usize + x as usize)
            .copied()
    }

    /// The colour as an `image` buffer (a copy).
    pub fn to_image(&self) -> image::RgbaImage {
        let mut buf = self.rgba.clone();
        // The fields are public; a caller who shrank `rgba` gets black, not a panic.
        buf.resize(self.width as usize * self.height as usize * 4, 0);
        image::RgbaImage::from_raw(self.width, self.height, buf).unwrap_or_default()
    }

    /// Writes the colour as an 8-bit RGBA PNG.
    pub fn save_png(&self, path: &Path) -> Result<()> {
        let image = self.to_image();
        crate::output::write_atomic(path, |w| {
            image
                .write_to(w, image::ImageFormat::Png)
                .map_err(|e| Error::Write {
                    path: path.to_path_buf(),
                    source: match e {
                        image::ImageError::IoError(io) => io,
                        other => std::io::Error::other(other),
                    },
                })
        })
    }
}
