//! Mutations of command text: bytes and words edited, numbers pushed to
//! and past their limits, lines of random words and random bytes.

use proptest::prelude::RngExt as _;
use proptest::test_runner::TestRng;

use super::text::{EDGE_NUMBERS, vocabulary_word};

/// A byte a mutation inserts: mostly what the grammar is made of.
fn random_byte(rng: &mut TestRng) -> u8 {
    const INTERESTING: &[u8] = b" \t=-+0123456789#*aeiouxyz";
    match rng.random_range(0..4) {
        0 => INTERESTING[rng.random_range(0..INTERESTING.len())],
        1 => rng.random_range(0x20..0x7f),
        _ => rng.random(),
    }
}

/// `line` with 1 to 4 random mutations: bytes flipped, replaced, inserted,
/// deleted or duplicated; words dropped, repeated or swapped; a number
/// replaced by one at or past a limit; a vocabulary word inserted.
pub fn mutate(line: &[u8], rng: &mut TestRng) -> Vec<u8> {
    let mut out = line.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        let len = out.len();
        let at = if len == 0 {
            0
        } else {
            rng.random_range(0..len)
        };
        match rng.random_range(0..10) {
            0 if len > 0 => out[at] ^= 1 << rng.random_range(0..8),
            1 if len > 0 => out[at] = random_byte(rng),
            2 => out.insert(at, random_byte(rng)),
            3 if len > 0 => {
                out.remove(at);
            }
            4 if len > 0 => {
                let end = rng.random_range(at..=len.min(at + 12));
                let copy = out[at..end].to_vec();
                out.splice(end..end, copy);
            }
            5 => out = edit_words(&out, rng),
            6 | 7 => out = replace_number(&out, rng),
            8 => {
                let word = vocabulary_word(rng);
                let mut piece = Vec::from(b" ".as_slice());
                piece.extend_from_slice(word.as_bytes());
                out.splice(at..at, piece);
            }
            _ => out.truncate(at),
        }
    }
    out
}

fn words(line: &[u8]) -> Vec<Vec<u8>> {
    line.split(|&b| b == b' ' || b == b'\t')
        .filter(|w| !w.is_empty())
        .map(<[u8]>::to_vec)
        .collect()
}

fn edit_words(line: &[u8], rng: &mut TestRng) -> Vec<u8> {
    let mut w = words(line);
    if w.is_empty() {
        return line.to_vec();
    }
    let i = rng.random_range(0..w.len());
    let j = rng.random_range(0..w.len());
    match rng.random_range(0..3) {
        0 => {
            w.remove(i);
        }
        1 => w.insert(i, w[j].clone()),
        _ => w.swap(i, j),
    }
    w.join(&b' ')
}

fn replace_number(line: &[u8], rng: &mut TestRng) -> Vec<u8> {
    let mut w = words(line);
    let numeric: Vec<usize> = (0..w.len())
        .filter(|&i| w[i].iter().any(u8::is_ascii_digit))
        .collect();
    let edge = EDGE_NUMBERS[rng.random_range(0..EDGE_NUMBERS.len())].as_bytes();
    if numeric.is_empty() {
        w.push(edge.to_vec());
    } else {
        let i = numeric[rng.random_range(0..numeric.len())];
        // Keep an option's name: `cycles=` + the new number.
        let keep = w[i].iter().position(|&b| b == b'=').map_or(0, |p| p + 1);
        w[i].truncate(keep);
        w[i].extend_from_slice(edge);
    }
    w.join(&b' ')
}

/// 1 to 8 random words of the vocabulary and edge numbers.
pub fn token_line(rng: &mut TestRng) -> Vec<u8> {
    let mut out = Vec::new();
    for i in 0..rng.random_range(1..=8) {
        if i > 0 {
            out.push(b' ');
        }
        let word = if rng.random_bool(0.7) {
            vocabulary_word(rng)
        } else {
            EDGE_NUMBERS[rng.random_range(0..EDGE_NUMBERS.len())]
        };
        out.extend_from_slice(word.as_bytes());
        if word.ends_with('=') {
            out.extend_from_slice(EDGE_NUMBERS[rng.random_range(0..EDGE_NUMBERS.len())].as_bytes());
        }
    }
    out
}

/// Up to `max` random bytes.
pub fn random_bytes(rng: &mut TestRng, max: usize) -> Vec<u8> {
    (0..rng.random_range(0..=max))
        .map(|_| rng.random())
        .collect()
}
