//! Line-oriented text parsing shared by the readers: every error names the file and the line.

use crate::IoError;
use std::path::Path;

/// Reads a whole file as UTF-8 text; invalid UTF-8 is a parse error at the line where it occurs.
pub(crate) fn read_text(path: &Path) -> Result<(String, String), IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::io(path, e))?;
    let name = path.display().to_string();
    let text = text_from_bytes(bytes, &name)?;
    Ok((text, name))
}

/// Converts bytes to text, naming the line of the first invalid UTF-8 sequence.
pub(crate) fn text_from_bytes(bytes: Vec<u8>, file: &str) -> Result<String, IoError> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count();
        IoError::Parse { file: file.to_string(), line, cause: "not valid UTF-8 text".into() }
    })
}

/// A cursor over the lines of a text, 1-based line numbers.
pub(crate) struct Lines<'a> {
    file: &'a str,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    /// Line number of the last line returned (0 before the first).
    pub(crate) line: usize,
    /// Lines starting with this character (after leading blanks) are skipped, and text after it is
    /// ignored.
    comment: Option<char>,
}

impl<'a> Lines<'a> {
    pub(crate) fn new(text: &'a str, file: &'a str, comment: Option<char>) -> Self {
        Lines { file, lines: text.lines().enumerate(), line: 0, comment }
    }

    /// An error at `line`.
    pub(crate) fn err_at(&self, line: usize, cause: impl Into<String>) -> IoError {
        IoError::Parse { file: self.file.to_string(), line, cause: cause.into() }
    }

    /// The next non-blank line with comments removed, trimmed, and its number.
    pub(crate) fn next_content(&mut self) -> Option<(usize, &'a str)> {
        for (i, raw) in self.lines.by_ref() {
            self.line = i + 1;
            let text = match self.comment {
                Some(c) => raw.split(c).next().unwrap_or(""),
                None => raw,
            };
            let text = text.trim();
            if !text.is_empty() {
                return Some((i + 1, text));
            }
        }
        self.line += 1;
        None
    }

    /// The next content line, or an "unexpected end of file" error saying what was expected.
    pub(crate) fn expect(&mut self, what: &str) -> Result<Tokens<'a>, IoError> {
        match self.next_content() {
            Some((line, text)) => Ok(Tokens::new(text, line, self.file)),
            None => Err(self.err_at(self.line, format!("unexpected end of file, expected {what}"))),
        }
    }
}

/// The whitespace-separated tokens of one line.
pub(crate) struct Tokens<'a> {
    pub(crate) text: &'a str,
    pub(crate) line: usize,
    file: &'a str,
    it: std::str::SplitWhitespace<'a>,
}

impl<'a> Tokens<'a> {
    pub(crate) fn new(text: &'a str, line: usize, file: &'a str) -> Self {
        Tokens { text, line, file, it: text.split_whitespace() }
    }

    /// An error at this line.
    pub(crate) fn err(&self, cause: impl Into<String>) -> IoError {
        IoError::Parse { file: self.file.to_string(), line: self.line, cause: cause.into() }
    }

    /// The next token as a string, if any.
    pub(crate) fn next_str(&mut self) -> Option<&'a str> {
        self.it.next()
    }

    fn token(&mut self, what: &str) -> Result<&'a str, IoError> {
        self.it.next().ok_or_else(|| self.err(format!("missing {what}")))
    }

    /// The next token as a non-negative integer.
    pub(crate) fn usize(&mut self, what: &str) -> Result<usize, IoError> {
        let t = self.token(what)?;
        t.parse().map_err(|_| self.err(format!("{what}: expected a non-negative integer, found `{t}`")))
    }

    /// The next token as a signed integer.
    pub(crate) fn i64(&mut self, what: &str) -> Result<i64, IoError> {
        let t = self.token(what)?;
        t.parse().map_err(|_| self.err(format!("{what}: expected an integer, found `{t}`")))
    }

    /// The next token as a finite real number.
    pub(crate) fn f64(&mut self, what: &str) -> Result<f64, IoError> {
        let t = self.token(what)?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.err(format!("{what}: non-finite value `{t}`"))),
            Err(_) => Err(self.err(format!("{what}: expected a number, found `{t}`"))),
        }
    }

    /// Three finite reals.
    pub(crate) fn xyz(&mut self, what: &str) -> Result<[f64; 3], IoError> {
        Ok([self.f64(what)?, self.f64(what)?, self.f64(what)?])
    }

    /// Fails if tokens remain.
    pub(crate) fn end(&mut self) -> Result<(), IoError> {
        match self.it.next() {
            None => Ok(()),
            Some(t) => Err(self.err(format!("unexpected trailing `{t}`"))),
        }
    }
}

/// A capacity hint that a corrupted count cannot turn into a huge allocation: at most one
/// element per byte of remaining input.
pub(crate) fn capacity(count: usize, text_len: usize) -> usize {
    count.min(text_len).min(1 << 24)
}
