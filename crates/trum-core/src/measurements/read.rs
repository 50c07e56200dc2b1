//! The reader: a small RFC 4180 tokenizer and the checks of the layout.

use super::{
    Column, ColumnSpec, ExtraColumn, MeasurementError, MeasurementErrorKind, Measurements, MisnameReason, NumberIssue,
    PlausibleRanges, COLUMNS,
};

/// One cell as tokenized: text (trimmed unless quoted) and whether it was quoted.
#[derive(Debug)]
struct Field {
    text: String,
    quoted: bool,
}

/// One record: its first line and its fields.
#[derive(Debug)]
struct Record {
    line: usize,
    fields: Vec<Field>,
}

/// A tokenizer error: line, 0-based field index, kind.
type LexError = (usize, usize, MeasurementErrorKind);

/// RFC 4180 tokenizer over validated UTF-8 text. Line ends are `\n`, `\r\n` or `\r`.
/// Works on bytes: every delimiter is ASCII, so slice positions are char boundaries.
struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Self {
        Lexer { text, pos: 0, line: 1 }
    }

    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    fn slice(&self, from: usize, to: usize) -> &'a str {
        self.text.get(from..to).unwrap_or("")
    }

    /// The next non-blank record, or `None` at the end of the text.
    fn next_record(&mut self) -> Result<Option<Record>, LexError> {
        loop {
            if self.pos >= self.text.len() {
                return Ok(None);
            }
            let line = self.line;
            let mut fields = Vec::new();
            loop {
                let field = self.field(fields.len())?;
                fields.push(field);
                match self.peek() {
                    Some(b',') => self.pos += 1,
                    Some(b'\r') => {
                        self.pos += 1;
                        if self.peek() == Some(b'\n') {
                            self.pos += 1;
                        }
                        self.line += 1;
                        break;
                    }
                    Some(b'\n') => {
                        self.pos += 1;
                        self.line += 1;
                        break;
                    }
                    _ => break,
                }
            }
            let blank = fields.len() == 1 && fields.iter().all(|f| !f.quoted && f.text.is_empty());
            if !blank {
                return Ok(Some(Record { line, fields }));
            }
        }
    }

    /// One field, leaving `pos` on the delimiter (`,`, a line end) or at the end.
    fn field(&mut self, index: usize) -> Result<Field, LexError> {
        let start = self.pos;
        while matches!(self.peek(), Some(b' ' | b'\t')) {
            self.pos += 1;
        }
        if self.peek() != Some(b'"') {
            self.pos = start;
            while !matches!(self.peek(), None | Some(b',' | b'\r' | b'\n')) {
                self.pos += 1;
            }
            return Ok(Field { text: self.slice(start, self.pos).trim().to_string(), quoted: false });
        }
        let open_line = self.line;
        self.pos += 1;
        let mut text = String::new();
        let mut seg = self.pos;
        loop {
            match self.peek() {
                None => return Err((open_line, index, MeasurementErrorKind::UnterminatedQuote)),
                Some(b'"') => {
                    text.push_str(self.slice(seg, self.pos));
                    self.pos += 1;
                    if self.peek() == Some(b'"') {
                        text.push('"');
                        self.pos += 1;
                        seg = self.pos;
                    } else {
                        break;
                    }
                }
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                }
                Some(b'\r') => {
                    self.pos += 1;
                    if self.peek() != Some(b'\n') {
                        self.line += 1;
                    }
                }
                Some(_) => self.pos += 1,
            }
        }
        while matches!(self.peek(), Some(b' ' | b'\t')) {
            self.pos += 1;
        }
        match self.peek() {
            None | Some(b',' | b'\r' | b'\n') => Ok(Field { text, quoted: true }),
            Some(_) => Err((self.line, index, MeasurementErrorKind::TextAfterQuote)),
        }
    }
}

/// Parses a cell of a numeric column: plain decimal or exponent form, optional sign.
pub(super) fn parse_number(text: &str) -> Result<f64, NumberIssue> {
    let b = text.as_bytes();
    let mut i = 0;
    if matches!(b.first(), Some(b'+' | b'-')) {
        i = 1;
    }
    let digits = |i: &mut usize| {
        let s = *i;
        while b.get(*i).is_some_and(u8::is_ascii_digit) {
            *i += 1;
        }
        *i - s
    };
    let int_digits = digits(&mut i);
    let mut frac_digits = 0;
    if b.get(i) == Some(&b'.') {
        i += 1;
        frac_digits = digits(&mut i);
    }
    let mantissa_ok = int_digits + frac_digits > 0;
    let mut exp_ok = true;
    let mut exp_start = None;
    if mantissa_ok && matches!(b.get(i), Some(b'e' | b'E')) {
        exp_start = Some(i);
        i += 1;
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        exp_ok = digits(&mut i) > 0;
    }
    if mantissa_ok && exp_ok && i == b.len() {
        let v: f64 = text.parse().map_err(|_| NumberIssue::NotANumber)?;
        return if v.is_finite() { Ok(v) } else { Err(NumberIssue::Overflow) };
    }
    // Classify the failure for a helpful message.
    let unsigned = text.trim_start_matches(['+', '-']).to_ascii_lowercase();
    if matches!(unsigned.as_str(), "nan" | "inf" | "infinity") {
        return Err(NumberIssue::NotFinite);
    }
    if unsigned.starts_with("0x") {
        return Err(NumberIssue::Hexadecimal);
    }
    if mantissa_ok && !exp_ok && exp_start.is_some() && i == b.len() {
        return Err(NumberIssue::IncompleteExponent);
    }
    if mantissa_ok && exp_ok {
        let rest = text.get(i..).unwrap_or("").trim();
        let is_unit = !rest.is_empty()
            && rest.len() <= 8
            && rest.chars().all(|c| c.is_alphabetic() || matches!(c, '/' | '·' | '°' | '%' | ' ' | '.' | '*'))
            && text.get(i..).is_some_and(|r| r.starts_with(' ') || rest.starts_with(char::is_alphabetic));
        if is_unit {
            return Err(NumberIssue::UnitInCell);
        }
    }
    Err(NumberIssue::NotANumber)
}

/// Unit spellings recognised after a quantity name in a header (lower case, separators
/// normalised to `_`), used only to suggest the right column name.
#[rustfmt::skip]
const UNIT_TOKENS: &[&str] = &[
    // force
    "n", "kn", "mn", "un", "newton", "newtons", "kgf", "gf", "lbf",
    // voltage
    "v", "kv", "mv", "vpp", "v_pp", "vp", "v_p", "vpk", "vrms", "v_rms", "rms", "volt", "volts",
    // frequency
    "hz", "khz", "mhz",
    // torque
    "nm", "n_m", "mnm", "mn_m", "m_nm", "knm", "nmm", "n_mm", "ncm", "n_cm", "ozin",
    // speed
    "rpm", "r_min", "rev_min", "1_min", "rad_s", "rad_per_s", "rads", "rps", "rev_s", "deg_s",
    // power, current, fraction
    "w", "mw", "kw", "watt", "watts", "a", "ma", "ua", "amp", "amps", "pct", "percent", "frac", "fraction",
    // temperature, time
    "c", "degc", "deg_c", "celsius", "k", "kelvin", "f", "degf", "deg_f",
    "s", "ms", "us", "sec", "secs", "seconds", "min", "h", "hr", "hours",
];

/// Header name normalised for suggestions: lower case, units in brackets joined with `_`,
/// separators (space, `-`, `/`, `.`, `·`, `*`) turned into single `_`, `°` dropped.
fn normalise_name(name: &str) -> String {
    let mut s = String::new();
    for ch in name.chars().flat_map(char::to_lowercase) {
        match ch {
            '°' => {}
            'µ' | 'μ' => s.push('u'),
            c if c.is_alphanumeric() => s.push(c),
            _ => {
                if !s.ends_with('_') {
                    s.push('_');
                }
            }
        }
    }
    s.trim_matches('_').to_string()
}

/// If a header name that is not a column looks like one in the wrong unit or spelling,
/// the column it means and how it differs.
pub(super) fn misnamed(name: &str) -> Option<(Column, MisnameReason)> {
    let norm = normalise_name(name);
    if norm.is_empty() {
        return None;
    }
    let mut best: Option<(usize, Column, MisnameReason)> = None;
    for spec in &COLUMNS {
        let canonical_stem = spec.name.strip_suffix(unit_suffix(spec)).unwrap_or(spec.name);
        let canonical_stem = canonical_stem.trim_end_matches('_');
        let stems = std::iter::once(canonical_stem).chain(spec.aliases.iter().copied());
        for stem in stems {
            let reason = if norm == stem {
                if spec.unit.is_empty() {
                    MisnameReason::Spelling
                } else {
                    MisnameReason::NoUnit
                }
            } else if let Some(rest) = norm.strip_prefix(stem).and_then(|r| r.strip_prefix('_')) {
                if !UNIT_TOKENS.contains(&rest) {
                    continue;
                }
                if !spec.unit.is_empty() && same_unit(rest, unit_suffix(spec)) {
                    MisnameReason::Spelling
                } else {
                    MisnameReason::WrongUnit
                }
            } else {
                continue;
            };
            // The longest matching stem wins (`speed_std` over `speed`).
            match best {
                Some((len, _, _)) if len >= stem.len() => {}
                _ => best = Some((stem.len(), spec.column, reason)),
            }
        }
    }
    best.map(|(_, c, r)| (c, r))
}

/// Whether a unit token (from [`UNIT_TOKENS`]) spells the layout's unit `suffix`.
fn same_unit(token: &str, suffix: &str) -> bool {
    let same: &[&str] = match suffix {
        "n" => &["n", "newton", "newtons"],
        "v" => &["v", "volt", "volts", "vp", "v_p", "vpk"],
        "hz" => &["hz"],
        "nm" => &["nm", "n_m"],
        "rpm" => &["rpm", "r_min", "rev_min", "1_min"],
        "w" => &["w", "watt", "watts"],
        "a" => &["a", "amp", "amps"],
        "c" => &["c", "degc", "deg_c", "celsius"],
        "s" => &["s", "sec", "secs", "seconds"],
        _ => &[],
    };
    same.contains(&token)
}

/// The unit suffix of a column name (`nm` for `torque_nm`), empty for unitless columns.
fn unit_suffix(spec: &ColumnSpec) -> &'static str {
    if spec.unit.is_empty() {
        return "";
    }
    spec.name.rsplit('_').next().unwrap_or("")
}

/// Reads a measurement file in the layout of docs/MEASUREMENTS.md.
///
/// `bytes` is the file's content; `source` names it in messages (usually the file name).
/// Follows the layout to the letter: UTF-8 (a leading BOM is skipped), comma-separated,
/// one header row, column order free, blank lines skipped, `\n`, `\r\n` or `\r` line
/// ends, cells trimmed of surrounding whitespace (inside quotes, kept), unknown columns
/// kept in [`Measurements::extra_columns`] with one warning naming them. Errors for:
/// non-UTF-8 bytes, an empty or header-only file, a missing required column, a duplicate
/// or empty column name, a column name that is a known quantity in the wrong unit or
/// spelling (unless the right column is present too), a ragged row, an unterminated
/// quote, an empty required cell, a numeric cell that is not a plain decimal (`nan`,
/// `inf`, hex, text), and a value outside its column's range. The first problem in file
/// order is reported. Never panics. Values must also lie in their column's default
/// plausible range ([`super::ColumnSpec::plausible`]); [`parse_measurements_with`] takes
/// other ranges.
pub fn parse_measurements(bytes: &[u8], source: &str) -> Result<Measurements, MeasurementError> {
    parse_measurements_with(bytes, source, &PlausibleRanges::default())
}

/// [`parse_measurements`] with the given plausible ranges (a value outside its column's
/// range is an error naming its line and column).
pub fn parse_measurements_with(
    bytes: &[u8],
    source: &str,
    plausible: &PlausibleRanges,
) -> Result<Measurements, MeasurementError> {
    let err = |line: Option<usize>, column: Option<String>, kind| MeasurementError {
        source_name: source.to_string(),
        line,
        column,
        kind,
    };
    if let Some(little_endian) = utf16(bytes) {
        return Err(err(Some(1), None, MeasurementErrorKind::Utf16 { little_endian }));
    }
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let (line, column) = locate_utf8_error(bytes, e.valid_up_to());
            let byte = bytes.get(e.valid_up_to()).copied().unwrap_or(0);
            return Err(err(Some(line), column, MeasurementErrorKind::NotUtf8 { byte_offset: e.valid_up_to(), byte }));
        }
    };
    let text = text.strip_prefix('\u{FEFF}').unwrap_or(text);
    let mut lexer = Lexer::new(text);
    let header = match lexer.next_record() {
        Ok(Some(h)) => h,
        Ok(None) => return Err(err(Some(1), None, MeasurementErrorKind::EmptyFile)),
        Err((line, _, kind)) => return Err(err(Some(line), None, kind)),
    };
    let header_line = header.line;
    let names: Vec<String> = header.fields.into_iter().map(|f| f.text).collect();
    let at_header = |column: Option<&str>, kind| err(Some(header_line), column.map(str::to_string), kind);

    // Header checks, in order: another separator, data instead of a header, empty names,
    // duplicates, misnamed quantities, missing required columns.
    if let [only] = names.as_slice() {
        if let Some(separator) = [';', '\t', '|'].into_iter().find(|c| only.contains(*c)) {
            return Err(at_header(None, MeasurementErrorKind::WrongDelimiter { separator }));
        }
    }
    if names.iter().all(|n| parse_number(n).is_ok()) {
        return Err(at_header(None, MeasurementErrorKind::NoHeader));
    }
    if let Some(i) = names.iter().position(String::is_empty) {
        return Err(at_header(None, MeasurementErrorKind::EmptyColumnName { field: i + 1 }));
    }
    // (a map: a header of 10^4 names is checked in linear time)
    let mut first_at: std::collections::HashMap<&str, usize> = std::collections::HashMap::with_capacity(names.len());
    for (j, n) in names.iter().enumerate() {
        if let Some(&i) = first_at.get(n.as_str()) {
            return Err(at_header(Some(n), MeasurementErrorKind::DuplicateColumn { first: i + 1, second: j + 1 }));
        }
        first_at.insert(n, j);
    }
    let known: Vec<Option<Column>> = names.iter().map(|n| Column::from_name(n)).collect();
    for (n, k) in names.iter().zip(&known) {
        if k.is_some() {
            continue;
        }
        if let Some((expected, reason)) = misnamed(n) {
            if !known.contains(&Some(expected)) {
                return Err(at_header(Some(n), MeasurementErrorKind::Misnamed { expected, reason }));
            }
        }
    }
    let missing: Vec<Column> = Column::REQUIRED.into_iter().filter(|c| !known.contains(&Some(*c))).collect();
    if !missing.is_empty() {
        return Err(at_header(None, MeasurementErrorKind::MissingColumns { columns: missing }));
    }

    let mut m = Measurements::default();
    let unknown: Vec<usize> = (0..names.len()).filter(|&i| known[i].is_none()).collect();
    for &i in &unknown {
        m.extra_columns.push(ExtraColumn { name: names[i].clone(), cells: Vec::new() });
    }
    for c in known.iter().flatten() {
        if *c == Column::RunId {
            m.run_id = Some(Vec::new());
        } else if let Some(slot) = m.optional_mut(*c) {
            *slot = Some(Vec::new());
        }
    }
    if !unknown.is_empty() {
        // the first ten by name, then a count: a warning stays one readable line
        let mut list: Vec<String> = unknown.iter().take(10).map(|&i| format!("'{}'", names[i])).collect();
        if unknown.len() > 10 {
            list.push(format!("and {} more", unknown.len() - 10));
        }
        let plural = if unknown.len() == 1 { "" } else { "s" };
        m.warnings.push(format!(
            "{source}: line {header_line}: ignoring unknown column{plural} {} (not part of the measurement layout)",
            list.join(", ")
        ));
    }

    // per header field, its place in `extra_columns` (unknown columns only)
    let mut extra_of_field: Vec<Option<usize>> = vec![None; names.len()];
    for (k, &i) in unknown.iter().enumerate() {
        extra_of_field[i] = Some(k);
    }
    loop {
        let record = match lexer.next_record() {
            Ok(Some(r)) => r,
            Ok(None) => break,
            Err((line, field, kind)) => return Err(err(Some(line), names.get(field).cloned(), kind)),
        };
        let line = record.line;
        let found = record.fields.len();
        if found > names.len() {
            return Err(err(Some(line), None, MeasurementErrorKind::TooManyFields { found, expected: names.len() }));
        }
        if found < names.len() {
            return Err(err(
                Some(line),
                names.get(found).cloned(),
                MeasurementErrorKind::TooFewFields { found, expected: names.len() },
            ));
        }
        for (f, ((field, name), col)) in record.fields.into_iter().zip(&names).zip(&known).enumerate() {
            let cell_err = |kind| err(Some(line), Some(name.clone()), kind);
            let Some(c) = *col else {
                if let Some(x) = extra_of_field[f].and_then(|k| m.extra_columns.get_mut(k)) {
                    x.cells.push(field.text);
                }
                continue;
            };
            if c == Column::RunId {
                let t = Some(field.text).filter(|t| !t.is_empty());
                m.run_id.get_or_insert_with(Vec::new).push(t);
                continue;
            }
            if field.text.trim().is_empty() {
                if c.is_required() {
                    return Err(cell_err(MeasurementErrorKind::EmptyRequiredCell { column: c }));
                }
                m.push_value(c, None);
                continue;
            }
            let text = field.text.trim();
            let value = parse_number(text).map_err(|issue| {
                cell_err(MeasurementErrorKind::BadNumber { column: c, text: text.to_string(), issue })
            })?;
            if c.check(value).is_err() {
                return Err(cell_err(MeasurementErrorKind::OutOfRange { column: c, text: text.to_string(), value }));
            }
            if !plausible.contains(c, value) {
                let (low, high) = plausible.get(c);
                return Err(cell_err(MeasurementErrorKind::Implausible {
                    column: c,
                    text: text.to_string(),
                    value,
                    low,
                    high,
                }));
            }
            m.push_value(c, Some(value));
        }
        m.lines.push(line);
    }
    if m.is_empty() {
        return Err(err(Some(header_line), None, MeasurementErrorKind::NoDataRows));
    }
    Ok(m)
}

/// `Some(little_endian)` when `bytes` look like UTF-16: a byte-order mark, or a zero in
/// every other byte of the start (ASCII text in UTF-16), which UTF-8 text never has.
fn utf16(bytes: &[u8]) -> Option<bool> {
    match bytes {
        [0xFF, 0xFE, ..] => return Some(true),
        [0xFE, 0xFF, ..] => return Some(false),
        _ => {}
    }
    let head = &bytes[..bytes.len().min(64) & !1];
    if head.len() < 4 {
        return None;
    }
    let zeros = |k: usize| head.iter().skip(k).step_by(2).all(|&b| b == 0);
    let ascii = |k: usize| head.iter().skip(k).step_by(2).all(|&b| b != 0 && b < 0x80);
    if zeros(1) && ascii(0) {
        Some(true)
    } else if zeros(0) && ascii(1) {
        Some(false)
    } else {
        None
    }
}

/// Line (1-based) and, when the header before it is intact, column of the first invalid
/// UTF-8 byte at `offset`.
fn locate_utf8_error(bytes: &[u8], offset: usize) -> (usize, Option<String>) {
    let valid = std::str::from_utf8(bytes.get(..offset).unwrap_or(&[])).unwrap_or("");
    let mut line = 1;
    let mut line_start = 0;
    let vb = valid.as_bytes();
    for (i, &b) in vb.iter().enumerate() {
        if b == b'\n' || (b == b'\r' && vb.get(i + 1) != Some(&b'\n')) {
            line += 1;
            line_start = i + 1;
        }
    }
    let valid = valid.strip_prefix('\u{FEFF}').unwrap_or(valid);
    let mut lexer = Lexer::new(valid);
    let header = match lexer.next_record() {
        Ok(Some(h)) if lexer.line <= line && h.line < line => h,
        _ => return (line, None),
    };
    let mut in_quotes = false;
    let mut field = 0;
    for &b in vb.get(line_start..).unwrap_or(&[]) {
        match b {
            b'"' => in_quotes = !in_quotes,
            b',' if !in_quotes => field += 1,
            _ => {}
        }
    }
    (line, header.fields.get(field).map(|f| f.text.clone()))
}
