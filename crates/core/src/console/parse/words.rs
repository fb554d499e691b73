//! The words of a line: tokens with their positions, keywords, numbers.

use const_format::utils::str_eq;

use crate::gestures::GestureKind;

use super::error::{ParseError, ParseErrorKind, Span};

/// A numeric field: its name and range (passed as `&'static`: one address
/// per call instead of the whole field).
#[derive(Clone, Copy)]
pub(super) struct Field {
    what: &'static str,
    min: i64,
    max: i64,
}

impl Field {
    /// A field named `what` over `min..=max`.
    pub(super) const fn new(what: &'static str, min: i64, max: i64) -> Self {
        Self { what, min, max }
    }
}

/// An error for an option seen before.
pub(super) fn once(seen: bool, word: Token<'_>) -> Result<(), ParseError> {
    if seen {
        Err(word.error(ParseErrorKind::DuplicateOption))
    } else {
        Ok(())
    }
}

/// A word of the line with its position.
#[derive(Clone, Copy)]
pub(super) struct Token<'a> {
    text: &'a [u8],
    start: usize,
}

/// A word compared without regard to ASCII case (`Other` if it matches
/// none of the names the parser asks about).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Word {
    Is(Kw),
    Other,
}

/// The protocol's keywords: each `Kw` variant with its word, lower case,
/// in one row (the enum, [`KEYWORDS`] and [`ALL`] come from this list, so
/// they cannot fall out of step).
macro_rules! keywords {
    ($($kw:ident $word:literal,)+) => {
        /// Every word the protocol has but the gestures' (those are the
        /// [gesture table](crate::gestures)'s). The parser matches these,
        /// not the texts: comparing one byte per arm instead of a string
        /// keeps it small.
        #[derive(Clone, Copy, PartialEq, Eq)]
        pub(super) enum Kw {
            $($kw,)+
        }

        /// Every word the protocol has but the gestures' (those are
        /// [`GestureKind::ALL`]'s), lower case, in the order of [`ALL`].
        pub const KEYWORDS: [&str; [$($word),+].len()] = [$($word),+];

        /// The [`Kw`] of each of [`KEYWORDS`].
        const ALL: [Kw; KEYWORDS.len()] = [$(Kw::$kw),+];
    };
}

keywords! {
    Help "help",
    Status "status",
    Save "save",
    Load "load",
    Defaults "defaults",
    Stop "stop",
    Look "look",
    Center "center",
    Centre "centre",
    Idle "idle",
    Seed "seed",
    Servo "servo",
    On "on",
    Off "off",
    Amp "amp",
    Random "random",
    Pitch "pitch",
    Roll "roll",
    Yaw "yaw",
    Neutral "neutral",
    Min "min",
    Max "max",
    PerDegree "per-degree",
    Direction "direction",
    Normal "normal",
    Reversed "reversed",
    Limits "limits",
    Stay "stay",
    Hold "hold",
    Cycles "cycles",
    Intensity "intensity",
    Watch "watch",
    Dmx "dmx",
    Address "address",
    Input "input",
    Button "button",
    Presence "presence",
    Rest "rest",
    Wake "wake",
    After "after",
    Never "never",
    Pose "pose",
    Relax "relax",
    Duck "duck",
    Radar "radar",
    Track "track",
    Height "height",
    Mount "mount",
    Prefer "prefer",
    Nearest "nearest",
    Newest "newest",
    Board "board",
    Paper "paper",
    Rate "rate",
}

/// [`KEYWORDS`]' indices with the words in byte order (they are lower case
/// and each once: checked here), for [`Token::lower`]'s bisection.
const SORTED: [u8; KEYWORDS.len()] = {
    assert!(KEYWORDS.len() <= u8::MAX as usize);
    let mut order = [0_u8; KEYWORDS.len()];
    let mut i = 0;
    while i < order.len() {
        order[i] = i as u8;
        let word = KEYWORDS[i].as_bytes();
        let mut b = 0;
        while b < word.len() {
            assert!(!word[b].is_ascii_uppercase(), "a keyword is lower case");
            b += 1;
        }
        i += 1;
    }
    // Insertion sort, at compile time.
    let mut i = 1;
    while i < order.len() {
        let mut j = i;
        while j > 0 && before(KEYWORDS[order[j] as usize], KEYWORDS[order[j - 1] as usize]) {
            let t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
            j -= 1;
        }
        i += 1;
    }
    let mut i = 1;
    while i < order.len() {
        assert!(
            before(KEYWORDS[order[i - 1] as usize], KEYWORDS[order[i] as usize]),
            "a keyword is listed twice"
        );
        i += 1;
    }
    order
};

/// Whether `a` comes before `b` in byte order.
const fn before(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let mut i = 0;
    while i < a.len() && i < b.len() {
        if a[i] != b[i] {
            return a[i] < b[i];
        }
        i += 1;
    }
    a.len() < b.len()
}

// A gesture's word must not be a word the protocol already has: the
// gesture would shadow it (or it the gesture). Checked when the crate
// compiles.
const _: () = {
    let mut k = 0;
    while k < GestureKind::COUNT {
        let mut i = 0;
        while i < KEYWORDS.len() {
            assert!(
                !str_eq(GestureKind::ALL[k].name(), KEYWORDS[i]),
                "a gesture's word is already a console word"
            );
            i += 1;
        }
        k += 1;
    }
};

impl<'a> Token<'a> {
    pub(super) fn span(&self) -> Span {
        Span {
            start: clamp_u16(self.start),
            end: clamp_u16(self.start + self.text.len()),
        }
    }

    pub(super) fn error(&self, kind: ParseErrorKind) -> ParseError {
        ParseError {
            kind,
            at: self.span(),
        }
    }

    /// The keyword this word is, ignoring ASCII case (by bisection of the
    /// keywords in byte order: a handful of comparisons, not one a keyword).
    pub(super) fn lower(&self) -> Word {
        let lowered = || self.text.iter().map(u8::to_ascii_lowercase);
        let (mut low, mut high) = (0, SORTED.len());
        while low < high {
            let mid = low + (high - low) / 2;
            let Some(&i) = SORTED.get(mid) else { break };
            let (Some(word), Some(&kw)) = (KEYWORDS.get(usize::from(i)), ALL.get(usize::from(i)))
            else {
                break;
            };
            match word.bytes().cmp(lowered()) {
                core::cmp::Ordering::Less => low = mid + 1,
                core::cmp::Ordering::Greater => high = mid,
                core::cmp::Ordering::Equal => return Word::Is(kw),
            }
        }
        Word::Other
    }

    /// The gesture this word names, ignoring ASCII case.
    pub(super) fn gesture(&self) -> Option<GestureKind> {
        GestureKind::from_name(self.text)
    }

    /// The word as a whole number in `field`'s range.
    pub(super) fn number(&self, field: &Field) -> Result<i64, ParseError> {
        let value = integer(self.text).ok_or(self.error(ParseErrorKind::NotANumber(field.what)))?;
        if value < field.min || value > field.max {
            return Err(self.error(ParseErrorKind::OutOfRange {
                what: field.what,
                min: field.min,
                max: field.max,
            }));
        }
        Ok(value)
    }

    /// `name=value` split at the first `=`, the name lower-cased.
    pub(super) fn split_option(&self) -> Option<(Word, Token<'a>)> {
        let eq = self.text.iter().position(|&b| b == b'=')?;
        let (name, rest) = self.text.split_at(eq);
        let value = Token {
            text: rest.get(1..).unwrap_or_default(),
            start: self.start + eq + 1,
        };
        let name = Token {
            text: name,
            start: self.start,
        };
        Some((name.lower(), value))
    }
}

const fn clamp_u16(v: usize) -> u16 {
    if v > u16::MAX as usize {
        u16::MAX
    } else {
        v as u16
    }
}

/// A decimal integer with an optional sign; `None` if not one. However
/// many digits it has, a number is a number: past ±`i64::MAX` it saturates
/// there, far outside every field's range, so that the range check rejects
/// it (`err range`) instead of calling it no number (`err syntax`).
fn integer(text: &[u8]) -> Option<i64> {
    let (negative, digits) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, text),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        value = value.saturating_mul(10).saturating_add(i64::from(d - b'0'));
    }
    Some(if negative {
        value.saturating_neg()
    } else {
        value
    })
}

/// The words of a line, separated by spaces and tabs.
pub(super) struct Words<'a> {
    line: &'a [u8],
    pos: usize,
}

impl<'a> Words<'a> {
    pub(super) fn new(line: &'a [u8]) -> Self {
        Self { line, pos: 0 }
    }

    /// An error at the end of the line (or at the current position).
    pub(super) fn error_here(&self, kind: ParseErrorKind) -> ParseError {
        let at = clamp_u16(self.line.len());
        ParseError {
            kind,
            at: Span { start: at, end: at },
        }
    }

    pub(super) fn skip_blanks(&mut self) {
        while let Some(&b) = self.line.get(self.pos) {
            if b != b' ' && b != b'\t' {
                break;
            }
            self.pos += 1;
        }
    }

    pub(super) fn peek(&mut self) -> Option<Token<'a>> {
        self.skip_blanks();
        let start = self.pos;
        let rest = self.line.get(start..).unwrap_or_default();
        let len = rest
            .iter()
            .position(|&b| b == b' ' || b == b'\t')
            .unwrap_or(rest.len());
        if len == 0 {
            return None;
        }
        Some(Token {
            text: rest.get(..len).unwrap_or_default(),
            start,
        })
    }

    pub(super) fn next(&mut self) -> Option<Token<'a>> {
        let token = self.peek()?;
        self.pos = token.start + token.text.len();
        Some(token)
    }

    /// A required number.
    pub(super) fn number(&mut self, field: &Field) -> Result<i64, ParseError> {
        match self.next() {
            Some(token) => token.number(field),
            None => Err(self.error_here(ParseErrorKind::Missing(field.what))),
        }
    }

    /// An optional positional number: absent at the end of the line or
    /// where the options (`name=value`) begin.
    pub(super) fn optional_number(&mut self, field: &Field) -> Result<Option<i64>, ParseError> {
        match self.peek() {
            Some(token) if !token.text.contains(&b'=') => {
                self.next();
                token.number(field).map(Some)
            }
            _ => Ok(None),
        }
    }

    /// The next `name=value` option, if any.
    pub(super) fn option(&mut self) -> Result<Option<(Word, Token<'a>, Token<'a>)>, ParseError> {
        let Some(token) = self.next() else {
            return Ok(None);
        };
        match token.split_option() {
            Some((name, value)) => Ok(Some((name, value, token))),
            None => Err(token.error(ParseErrorKind::Unexpected)),
        }
    }

    /// Nothing may follow.
    pub(super) fn end(&mut self) -> Result<(), ParseError> {
        match self.next() {
            Some(token) => Err(token.error(ParseErrorKind::Unexpected)),
            None => Ok(()),
        }
    }
}
