//! The little-endian byte format shared by checkpoints ([`crate::checkpoint`]) and the resume
//! states the observers save in them ([`crate::output::Observer::resume_state`]): u64 counts,
//! f64 bit patterns, length-prefixed UTF-8 strings and byte strings. One list of fields,
//! visited through a [`Codec`], serves both writing ([`Enc`]) and reading ([`Dec`]).

/// One direction of the byte format of checkpoints and of the observers' resume states: [`Enc`] writes each value it is shown,
/// [`Dec`] overwrites it with the next value read.
pub(crate) trait Codec {
    fn u64(&mut self, x: &mut u64) -> Result<(), String>;
    fn i32(&mut self, x: &mut i32) -> Result<(), String>;
    /// A count, then resizes `items` to it (reading) or writes their number (writing);
    /// each item takes at least `item_bytes` bytes (checked against what is left).
    fn count<T: Clone + Default>(
        &mut self,
        items: &mut Vec<T>,
        item_bytes: usize,
    ) -> Result<(), String>;
    fn bytes(&mut self, x: &mut Vec<u8>) -> Result<(), String>;

    fn usize(&mut self, x: &mut usize) -> Result<(), String> {
        let mut v = *x as u64;
        self.u64(&mut v)?;
        *x = usize::try_from(v).map_err(|_| "a count does not fit in memory".to_string())?;
        Ok(())
    }
    fn f64(&mut self, x: &mut f64) -> Result<(), String> {
        let mut bits = x.to_bits();
        self.u64(&mut bits)?;
        *x = f64::from_bits(bits);
        Ok(())
    }
    fn f64s(&mut self, x: &mut Vec<f64>) -> Result<(), String> {
        self.count(x, 8)?;
        x.iter_mut().try_for_each(|v| self.f64(v))
    }
    fn str(&mut self, s: &mut String) -> Result<(), String> {
        let mut b = std::mem::take(s).into_bytes();
        self.bytes(&mut b)?;
        *s = String::from_utf8(b).map_err(|_| "a name is not UTF-8".to_string())?;
        Ok(())
    }
}

pub(crate) struct Enc(pub(crate) Vec<u8>);

impl Codec for Enc {
    fn u64(&mut self, x: &mut u64) -> Result<(), String> {
        self.0.extend_from_slice(&x.to_le_bytes());
        Ok(())
    }
    fn i32(&mut self, x: &mut i32) -> Result<(), String> {
        self.0.extend_from_slice(&x.to_le_bytes());
        Ok(())
    }
    fn count<T: Clone + Default>(&mut self, items: &mut Vec<T>, _: usize) -> Result<(), String> {
        self.u64(&mut (items.len() as u64))
    }
    fn bytes(&mut self, x: &mut Vec<u8>) -> Result<(), String> {
        self.u64(&mut (x.len() as u64))?;
        self.0.extend_from_slice(x);
        Ok(())
    }
}

pub(crate) struct Dec<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) pos: usize,
}

impl Dec<'_> {
    pub(crate) fn take(&mut self, n: usize) -> Result<&[u8], String> {
        if self.bytes.len() - self.pos < n {
            return Err(format!("it ends early (at byte {})", self.pos));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    /// A count of items of at least `item_bytes` bytes each, checked against what is left.
    fn len(&mut self, item_bytes: usize) -> Result<usize, String> {
        let mut n = 0;
        self.usize(&mut n)?;
        if n.saturating_mul(item_bytes) > self.bytes.len() - self.pos {
            return Err(format!("a count ({n}) exceeds the file's size"));
        }
        Ok(n)
    }
}

impl Codec for Dec<'_> {
    fn u64(&mut self, x: &mut u64) -> Result<(), String> {
        *x = u64::from_le_bytes(self.take(8)?.try_into().unwrap());
        Ok(())
    }
    fn i32(&mut self, x: &mut i32) -> Result<(), String> {
        *x = i32::from_le_bytes(self.take(4)?.try_into().unwrap());
        Ok(())
    }
    fn count<T: Clone + Default>(
        &mut self,
        items: &mut Vec<T>,
        item_bytes: usize,
    ) -> Result<(), String> {
        let n = self.len(item_bytes)?;
        items.clear();
        items.resize(n, T::default());
        Ok(())
    }
    fn bytes(&mut self, x: &mut Vec<u8>) -> Result<(), String> {
        let n = self.len(1)?;
        *x = self.take(n)?.to_vec();
        Ok(())
    }
}

impl<'a> Dec<'a> {
    /// A reader of `bytes` from their start.
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Dec { bytes, pos: 0 }
    }

    /// Err unless every byte was read.
    pub(crate) fn finish(&self) -> Result<(), String> {
        if self.pos == self.bytes.len() {
            Ok(())
        } else {
            Err(format!(
                "{} unexpected bytes after the last field",
                self.bytes.len() - self.pos
            ))
        }
    }
}

/// The bytes that `write` puts through an [`Enc`].
pub(crate) fn encode_with(write: impl FnOnce(&mut Enc) -> Result<(), String>) -> Vec<u8> {
    let mut e = Enc(Vec::new());
    write(&mut e).expect("writing to memory cannot fail");
    e.0
}

/// What `read` takes from `bytes` through a [`Dec`], which must use every byte.
pub(crate) fn decode_with<T>(
    bytes: &[u8],
    read: impl FnOnce(&mut Dec) -> Result<T, String>,
) -> Result<T, String> {
    let mut d = Dec::new(bytes);
    let value = read(&mut d)?;
    d.finish()?;
    Ok(value)
}
