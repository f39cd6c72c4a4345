//! Little-endian reads from the bytes of a `.vdb` file, every one checked against the end.

use glam::{DVec3, IVec3};

/// Why bytes could not be read: the byte offset and what was being read.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Malformed {
    /// Byte offset in the file.
    pub offset: usize,
    /// What is wrong there.
    pub message: String,
}

/// Result of a read from a [`Cursor`].
pub(super) type Read<T> = Result<T, Malformed>;

/// A position in the bytes of a file.
pub(super) struct Cursor<'a> {
    bytes: &'a [u8],
    offset: usize,
}

impl<'a> Cursor<'a> {
    /// A cursor at `offset` in `bytes`.
    pub fn at(bytes: &'a [u8], offset: usize) -> Cursor<'a> {
        Cursor { bytes, offset }
    }

    /// The offset of the next byte.
    pub fn offset(&self) -> usize {
        self.offset
    }

    /// Bytes left after the cursor.
    pub fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.offset)
    }

    /// An error at the cursor.
    pub fn error<T>(&self, message: impl Into<String>) -> Read<T> {
        Err(Malformed {
            offset: self.offset,
            message: message.into(),
        })
    }

    /// The next `n` bytes (`what` names them in the error when the file ends first).
    pub fn take(&mut self, n: usize, what: &str) -> Read<&'a [u8]> {
        if n > self.remaining() {
            return self.error(format!(
                "the file ends after {} bytes, within {what} ({n} bytes)",
                self.bytes.len()
            ));
        }
        let taken = &self.bytes[self.offset..self.offset + n];
        self.offset += n;
        Ok(taken)
    }

    /// The next `N` bytes as an array.
    pub fn array<const N: usize>(&mut self, what: &str) -> Read<[u8; N]> {
        Ok(self.take(N, what)?.try_into().expect("N bytes"))
    }

    /// A byte.
    pub fn u8(&mut self, what: &str) -> Read<u8> {
        Ok(self.array::<1>(what)?[0])
    }

    /// A `u32`.
    pub fn u32(&mut self, what: &str) -> Read<u32> {
        self.array(what).map(u32::from_le_bytes)
    }

    /// An `i32`.
    pub fn i32(&mut self, what: &str) -> Read<i32> {
        self.array(what).map(i32::from_le_bytes)
    }

    /// An `i64`.
    pub fn i64(&mut self, what: &str) -> Read<i64> {
        self.array(what).map(i64::from_le_bytes)
    }

    /// An `f32`.
    pub fn f32(&mut self, what: &str) -> Read<f32> {
        self.array(what).map(f32::from_le_bytes)
    }

    /// Three `f64`s (OpenVDB's `Vec3d`).
    pub fn dvec3(&mut self, what: &str) -> Read<DVec3> {
        let mut v = [0.0; 3];
        for c in &mut v {
            *c = f64::from_le_bytes(self.array(what)?);
        }
        Ok(DVec3::from_array(v))
    }

    /// Three `i32`s (OpenVDB's `Coord`).
    pub fn ivec3(&mut self, what: &str) -> Read<IVec3> {
        Ok(IVec3::new(
            self.i32(what)?,
            self.i32(what)?,
            self.i32(what)?,
        ))
    }

    /// A count that the rest of the file must hold at least `min_bytes_each` bytes for.
    pub fn count(&mut self, what: &str, min_bytes_each: usize) -> Read<usize> {
        let start = self.offset;
        let n = self.u32(what)? as usize;
        if n.saturating_mul(min_bytes_each) > self.remaining() {
            self.offset = start;
            return self.error(format!(
                "{what} is {n}, more than the {} bytes left could hold",
                self.remaining()
            ));
        }
        Ok(n)
    }

    /// A string: a `u32` length and that many bytes (OpenVDB's `readString`).
    pub fn string(&mut self, what: &str) -> Read<String> {
        let n = self.count(what, 1)?;
        Ok(String::from_utf8_lossy(self.take(n, what)?).into_owned())
    }

    /// Moves the cursor to `offset`, which must lie in the file.
    pub fn seek(&mut self, offset: i64, what: &str) -> Read<()> {
        match usize::try_from(offset) {
            Ok(o) if o <= self.bytes.len() => {
                self.offset = o;
                Ok(())
            }
            _ => self.error(format!(
                "{what} is at byte {offset}, outside the file's {} bytes",
                self.bytes.len()
            )),
        }
    }
}
