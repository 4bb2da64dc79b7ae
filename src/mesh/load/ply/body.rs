//! Where the binary reader takes its bytes from: a payload in memory, or a
//! file read a chunk at a time into one reused buffer.

use std::io::{ErrorKind, Read};
use std::path::Path;

use crate::error::{Error, Result};

/// How many bytes [`FileBody`] reads at a time, and about how many the
/// fixed-row reader asks for at once.
pub(super) const BODY_CHUNK: usize = 1 << 20;

/// The payload of a binary file, read in order.
pub(super) trait Body {
    /// The next `n` bytes, or fewer where the payload ends.
    fn take(&mut self, n: usize) -> Result<&[u8]>;
    /// The next `n` bytes (or fewer where the payload ends) without taking
    /// them: the next call sees them again.
    fn peek(&mut self, n: usize) -> Result<&[u8]>;
    /// Takes `n` bytes that [`Body::peek`] has just shown.
    fn skip(&mut self, n: usize);
}

/// A payload in memory.
pub(super) struct SliceBody<'a>(pub(super) &'a [u8]);

impl Body for SliceBody<'_> {
    #[inline]
    fn take(&mut self, n: usize) -> Result<&[u8]> {
        let (head, rest) = self.0.split_at(n.min(self.0.len()));
        self.0 = rest;
        Ok(head)
    }

    #[inline]
    fn peek(&mut self, n: usize) -> Result<&[u8]> {
        Ok(&self.0[..n.min(self.0.len())])
    }

    #[inline]
    fn skip(&mut self, n: usize) {
        self.0 = &self.0[n..];
    }
}

/// A payload read from a file [`BODY_CHUNK`] bytes at a time into one
/// buffer that is reused (and grown only for a longer request, and only as
/// far as the file holds bytes), so that a large file is never copied whole
/// into fresh memory.
pub(super) struct FileBody<'p, R> {
    pub(super) r: R,
    pub(super) path: &'p Path,
    pub(super) buf: Vec<u8>,
    pub(super) start: usize,
    pub(super) end: usize,
    pub(super) eof: bool,
}

impl<R: Read> Body for FileBody<'_, R> {
    #[inline]
    fn take(&mut self, n: usize) -> Result<&[u8]> {
        if self.end - self.start < n && !self.eof {
            self.fill(n)?;
        }
        let k = n.min(self.end - self.start);
        let out = &self.buf[self.start..self.start + k];
        self.start += k;
        Ok(out)
    }

    #[inline]
    fn peek(&mut self, n: usize) -> Result<&[u8]> {
        if self.end - self.start < n && !self.eof {
            self.fill(n)?;
        }
        Ok(&self.buf[self.start..self.start + n.min(self.end - self.start)])
    }

    #[inline]
    fn skip(&mut self, n: usize) {
        assert!(n <= self.end - self.start, "skipped more than was shown");
        self.start += n;
    }
}

impl<R: Read> FileBody<'_, R> {
    /// Reads until `n` bytes are buffered or the file ends.
    #[cold]
    fn fill(&mut self, n: usize) -> Result<()> {
        self.buf.copy_within(self.start..self.end, 0);
        self.end -= self.start;
        self.start = 0;
        if self.buf.len() < BODY_CHUNK {
            self.buf.resize(BODY_CHUNK, 0);
        }
        while self.end < n && !self.eof {
            if self.end == self.buf.len() {
                // Full and still short: grow, doubling, as bytes arrive.
                let len = self.buf.len();
                self.buf.resize(len.saturating_mul(2).min(n.max(len)), 0);
            }
            match self.r.read(&mut self.buf[self.end..]) {
                Ok(0) => self.eof = true,
                Ok(got) => self.end += got,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(source) => {
                    return Err(Error::Io {
                        path: self.path.to_path_buf(),
                        source,
                    });
                }
            }
        }
        Ok(())
    }
}
