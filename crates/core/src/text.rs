//! Messages written without `core::fmt`.
//!
//! The console's replies and the error reasons they carry are written
//! through [`Text`]: strings, and integers in decimal. `core::fmt` does the
//! same with padding, alignment and dynamic dispatch per argument, which
//! costs the console image about 5 KB of flash; this costs a few hundred
//! bytes. Every error type implements [`Describe`] once, and its `Display`
//! is that same text (through [`display`]), so the host, the tests and the
//! board all read one wording.
//!
//! ```
//! use idle_head_core::text::{Describe, Text, display};
//!
//! struct Late(u64);
//! impl Describe for Late {
//!     fn describe(&self, out: &mut dyn Text) {
//!         out.str("woke ").u64(self.0).str(" us late, ").i64(-7).str(" dB, 0x").hex2(0x0a);
//!     }
//! }
//! impl core::fmt::Display for Late {
//!     fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
//!         display(self, f)
//!     }
//! }
//!
//! assert_eq!(Late(42).to_string(), "woke 42 us late, -7 dB, 0x0a");
//! ```

use core::fmt;

/// Where a message is written: a console reply, a `fmt::Formatter`.
pub trait Text {
    /// Appends `s`.
    fn put(&mut self, s: &str);
}

/// A message that writes itself into a [`Text`].
pub trait Describe {
    /// Writes the message.
    fn describe(&self, out: &mut dyn Text);
}

impl dyn Text + '_ {
    /// Appends `s`.
    pub fn str(&mut self, s: &str) -> &mut Self {
        self.put(s);
        self
    }

    /// Appends `n` in decimal.
    pub fn u64(&mut self, n: u64) -> &mut Self {
        self.zeros(n, 1)
    }

    /// Appends `n` in decimal, with a `-` if negative.
    pub fn i64(&mut self, n: i64) -> &mut Self {
        if n < 0 {
            self.put("-");
        }
        self.u64(n.unsigned_abs())
    }

    /// Appends `n` in decimal with at least `width` digits (leading zeros).
    pub fn zeros(&mut self, n: u64, width: usize) -> &mut Self {
        // u64::MAX has 20 digits.
        const MOST: usize = 20;
        let mut digits = [b'0'; MOST];
        let mut start = MOST;
        // The digits below 2^32 in 32-bit arithmetic: a Cortex-M0+ divides
        // a u64 in software, at hundreds of instructions a digit.
        let (mut high, mut low) = match u32::try_from(n) {
            Ok(low) => (0, low),
            Err(_) => (n / 1_000_000_000, (n % 1_000_000_000) as u32),
        };
        for slot in digits.iter_mut().rev() {
            if high == 0 && low == 0 && MOST - start >= width {
                break;
            }
            *slot = b'0' + (low % 10) as u8;
            low /= 10;
            start -= 1;
            // Nine digits of `low` are out: the next come from `high`.
            if high != 0 && (MOST - start).is_multiple_of(9) {
                low = (high % 1_000_000_000) as u32;
                high /= 1_000_000_000;
            }
        }
        if let Some(Ok(s)) = digits.get(start..).map(core::str::from_utf8) {
            self.put(s);
        }
        self
    }

    /// Appends `n` thousandths as a decimal number without trailing zeros
    /// (`6666` is `6.666`, `12500` is `12.5`, `4000` is `4`): millidegrees
    /// as degrees, milliseconds as seconds.
    pub fn milli(&mut self, n: u64) -> &mut Self {
        // n % 1000 < 1000.
        let (fraction, digits) = significant((n % 1000) as u32);
        self.u64(n / 1000);
        if digits == 0 {
            return self;
        }
        self.put(".");
        self.zeros(u64::from(fraction), digits)
    }

    /// Appends `byte` as two lowercase hexadecimal digits.
    pub fn hex2(&mut self, byte: u8) -> &mut Self {
        let pair = [hex_digit(byte >> 4), hex_digit(byte)];
        if let Ok(s) = core::str::from_utf8(&pair) {
            self.put(s);
        }
        self
    }

    /// Appends what `message` describes.
    pub fn with(&mut self, message: &dyn Describe) -> &mut Self {
        message.describe(self);
        self
    }

    /// Appends `template` with each `{}` in it replaced by the next of
    /// `args` (a `{}` without an argument is dropped). One call with a
    /// table of arguments takes less flash than a call per piece.
    pub fn fill(&mut self, template: &str, args: &[Arg<'_>]) -> &mut Self {
        let bytes = template.as_bytes();
        let mut args = args.iter();
        let (mut from, mut at) = (0, 0);
        while at < bytes.len() {
            if !(bytes.get(at) == Some(&b'{') && bytes.get(at + 1) == Some(&b'}')) {
                at += 1;
                continue;
            }
            self.put(template.get(from..at).unwrap_or_default());
            match args.next() {
                Some(Arg::Str(s)) => self.put(s),
                Some(&Arg::Uint(n)) => {
                    self.u64(n);
                }
                Some(&Arg::Int(n)) => {
                    self.i64(n);
                }
                Some(Arg::Text(message)) => message.describe(self),
                None => {}
            }
            at += 2;
            from = at;
        }
        self.put(template.get(from..).unwrap_or_default());
        self
    }
}

/// An argument of `fill` (a method of every `dyn Text`).
#[derive(Clone, Copy)]
pub enum Arg<'a> {
    /// A string.
    Str(&'a str),
    /// An unsigned integer, in decimal.
    Uint(u64),
    /// A signed integer, in decimal.
    Int(i64),
    /// A message.
    Text(&'a dyn Describe),
}

/// A fraction of thousandths (`0..1000`) as a decimal number writes it:
/// its significant digits and how many (`500` is `(5, 1)`, `250` is
/// `(25, 2)`, `0` is `(0, 0)`).
pub(crate) const fn significant(thousandths: u32) -> (u32, usize) {
    let (mut fraction, mut digits) = (thousandths, 3);
    while digits > 0 && fraction % 10 == 0 {
        fraction /= 10;
        digits -= 1;
    }
    (fraction, digits)
}

/// The lowercase hexadecimal digit of `v`'s low four bits.
pub(crate) const fn hex_digit(v: u8) -> u8 {
    match v & 0xf {
        d @ 0..=9 => b'0' + d,
        d => b'a' + d - 10,
    }
}

/// Writes `message` into a `fmt::Formatter`: the body of a `Display`.
///
/// # Errors
/// The formatter's first error.
pub fn display(message: &dyn Describe, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    struct Fmt<'a, 'b> {
        f: &'a mut fmt::Formatter<'b>,
        result: fmt::Result,
    }
    impl Text for Fmt<'_, '_> {
        fn put(&mut self, s: &str) {
            if self.result.is_ok() {
                self.result = self.f.write_str(s);
            }
        }
    }
    let mut out = Fmt { f, result: Ok(()) };
    message.describe(&mut out);
    out.result
}

/// Text written into a byte buffer, cut where the buffer ends: a Bottango
/// answer, a telemetry line. (A console [`Reply`](crate::console::Reply)
/// is another [`Text`]: it keeps its line whole and marks a cut.)
///
/// ```
/// use idle_head_core::text::Out;
///
/// let mut buf = [0; 8];
/// let mut out = Out::new(&mut buf);
/// out.put(b"MOD,").text().u64(96).str(",1234\n");
/// assert_eq!(out.into_bytes(), b"MOD,96,1");
/// ```
#[derive(Debug)]
pub struct Out<'b> {
    buf: &'b mut [u8],
    len: usize,
}

impl<'b> Out<'b> {
    /// Nothing written yet, into `buf`.
    #[must_use]
    pub fn new(buf: &'b mut [u8]) -> Self {
        Self { buf, len: 0 }
    }

    /// Appends `bytes` (as much as fits).
    #[inline(never)]
    pub fn put(&mut self, bytes: &[u8]) -> &mut Self {
        let room = self.buf.get_mut(self.len..).unwrap_or_default();
        let n = room.len().min(bytes.len());
        for (d, s) in room.iter_mut().zip(bytes) {
            *d = *s;
        }
        self.len += n;
        self
    }

    /// The same buffer as a [`Text`], for numbers and messages.
    pub fn text(&mut self) -> &mut dyn Text {
        self
    }

    /// How many bytes are written.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing is written.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The bytes written so far.
    #[must_use]
    pub fn written(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or_default()
    }

    /// The bytes written.
    #[must_use]
    pub fn into_bytes(self) -> &'b [u8] {
        let len = self.len;
        let buf: &'b [u8] = self.buf;
        buf.get(..len).unwrap_or_default()
    }
}

impl Text for Out<'_> {
    fn put(&mut self, s: &str) {
        Out::put(self, s.as_bytes());
    }
}

/// Implements `Display` for types that implement [`Describe`].
macro_rules! display_from_describe {
    ($($t:ty),+ $(,)?) => {$(
        impl core::fmt::Display for $t {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                $crate::text::display(self, f)
            }
        }
    )+};
}
pub(crate) use display_from_describe;
