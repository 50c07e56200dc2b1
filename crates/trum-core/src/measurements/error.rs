//! Why measurement data does not fit the layout, with the messages the user reads.

use super::Column;

/// A measurement file (or synthetic data) that does not fit the layout.
///
/// Displays as `SOURCE: line N, column 'NAME': WHY`; the line part is left out only when
/// no line applies, the column part when the problem is not one column (a ragged row, an
/// empty file, missing columns, which the reason then names).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{source_name}{}: {kind}", location(*.line, .column.as_deref()))]
pub struct MeasurementError {
    /// Where the data came from (file name, or `synthetic data` for the builder).
    pub source_name: String,
    /// 1-based line in the source text.
    pub line: Option<usize>,
    /// Column name as written in the header, when the problem is one column.
    pub column: Option<String>,
    /// What is wrong.
    pub kind: MeasurementErrorKind,
}

fn location(line: Option<usize>, column: Option<&str>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!(": line {l}, column '{c}'"),
        (Some(l), None) => format!(": line {l}"),
        (None, Some(c)) => format!(": column '{c}'"),
        (None, None) => String::new(),
    }
}

/// Why a number cell was rejected before its range was checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NumberIssue {
    /// Text that is not a decimal number.
    NotANumber,
    /// `nan`, `inf`, `infinity` (any case, any sign).
    NotFinite,
    /// `0x…` hexadecimal.
    Hexadecimal,
    /// An exponent marker without digits (`1.5e`, `2e+`), typically a truncated line.
    IncompleteExponent,
    /// A number followed by a unit (`12 N`).
    UnitInCell,
    /// A well-formed number too large for a 64-bit float (`1e400`).
    Overflow,
}

/// Why a header name that is not a column of the layout was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MisnameReason {
    /// The quantity with a unit suffix other than the layout's (`preload_kn`).
    WrongUnit,
    /// The quantity without any unit suffix (`torque`).
    NoUnit,
    /// The right quantity and unit spelled differently (`Preload_N`, `temp_c`).
    Spelling,
}

/// What is wrong, with the structured details.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasurementErrorKind {
    /// The bytes are not UTF-8.
    #[error("byte 0x{byte:02X} at offset {byte_offset} is not valid UTF-8; save the file as UTF-8")]
    NotUtf8 {
        /// 0-based byte offset of the first invalid byte.
        byte_offset: usize,
        /// The invalid byte.
        byte: u8,
    },
    /// The bytes are UTF-16 (a byte-order mark, or a zero byte beside every ASCII one).
    #[error("the file is UTF-16{}, not UTF-8; save it as UTF-8 (in a spreadsheet: CSV UTF-8)", if *.little_endian { " (little-endian)" } else { " (big-endian)" })]
    Utf16 {
        /// Byte order.
        little_endian: bool,
    },
    /// The header is one field holding another separator.
    #[error("the header is one column holding '{separator}': the file looks separated by '{separator}' (a spreadsheet's regional setting?); measurement files are comma-separated, with '.' as the decimal point")]
    WrongDelimiter {
        /// The separator found (`;`, a tab, `|`).
        separator: char,
    },
    /// Nothing but blank lines (or nothing at all).
    #[error("no data rows: the file is empty; expected a header row and at least one measurement row")]
    EmptyFile,
    /// A header and no rows.
    #[error("no data rows: the header is not followed by any measurement row")]
    NoDataRows,
    /// The first row holds numbers only.
    #[error(
        "the first row looks like data, not a header; the file must start with a header row such as \
         preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm"
    )]
    NoHeader,
    /// A header field is empty.
    #[error("header field {field} is empty; every column needs a name")]
    EmptyColumnName {
        /// 1-based field position in the header.
        field: usize,
    },
    /// A name appears twice in the header.
    #[error("appears twice in the header (fields {first} and {second}); column names must be unique")]
    DuplicateColumn {
        /// 1-based position of the first occurrence.
        first: usize,
        /// 1-based position of the second occurrence.
        second: usize,
    },
    /// A header name that looks like a known quantity in the wrong unit or spelling.
    #[error("{}", misnamed_message(*.expected, *.reason))]
    Misnamed {
        /// The column the name most likely means.
        expected: Column,
        /// How it differs.
        reason: MisnameReason,
    },
    /// Required columns absent from the header.
    #[error("{}", missing_message(.columns))]
    MissingColumns {
        /// The missing required columns, in layout order.
        columns: Vec<Column>,
    },
    /// A quoted cell never closed before the end of the file.
    #[error("a quoted cell opens on this line and is never closed")]
    UnterminatedQuote,
    /// Text between a closing quote and the next comma.
    #[error("unexpected text after the closing quote of a quoted cell")]
    TextAfterQuote,
    /// A row with fewer fields than the header has columns.
    #[error("the row has {found} fields but the header has {expected} columns; this column and the ones after it have no cell")]
    TooFewFields {
        /// Fields in the row.
        found: usize,
        /// Columns in the header.
        expected: usize,
    },
    /// A row with more fields than the header has columns.
    #[error("the row has {found} fields but the header has {expected} columns")]
    TooManyFields {
        /// Fields in the row.
        found: usize,
        /// Columns in the header.
        expected: usize,
    },
    /// An empty cell in a required column.
    #[error("empty cell in a required column; every row needs a {} in {}", .column.spec().quantity, .column.spec().unit)]
    EmptyRequiredCell {
        /// The required column.
        column: Column,
    },
    /// A cell that is not a plain decimal number.
    #[error("{}", number_message(*.column, .text, *.issue))]
    BadNumber {
        /// The numeric column.
        column: Column,
        /// The cell text (trimmed).
        text: String,
        /// What is wrong with it.
        issue: NumberIssue,
    },
    /// A number outside the column's range.
    #[error("\"{text}\" {}; {}", .column.check(*.value).err().unwrap_or("is out of range"), .column.requirement())]
    OutOfRange {
        /// The column.
        column: Column,
        /// The cell text as written (for the builder, the value formatted as it would be written).
        text: String,
        /// The parsed value.
        value: f64,
    },
    /// A number inside the column's range but outside its plausible range.
    #[error(
        "\"{text}\" is outside the plausible range of {} for a traveling-wave ultrasonic motor, {} \
         (a typo, a unit slip or a bench fault?); if the value is real, give the column another \
         plausible range (docs/MEASUREMENTS.md, \"Plausible ranges\")",
        .column.spec().quantity,
        super::plausible::describe(*.column, (*.low, *.high))
    )]
    Implausible {
        /// The column.
        column: Column,
        /// The cell text as written.
        text: String,
        /// The parsed value.
        value: f64,
        /// Low end of the plausible range in force.
        low: f64,
        /// High end of the plausible range in force.
        high: f64,
    },
    /// A `run_id` given to the builder that contains a line break.
    #[error("contains a line break; run ids must be one line")]
    LineBreakInText,
}

fn misnamed_message(expected: Column, reason: MisnameReason) -> String {
    let s = expected.spec();
    let how = match reason {
        MisnameReason::WrongUnit => " in the wrong unit",
        MisnameReason::NoUnit => " without a unit",
        MisnameReason::Spelling => "",
    };
    let exactly = if reason == MisnameReason::Spelling { "exactly " } else { "" };
    format!("looks like {}{how}; trum expects {exactly}'{}' ({})", s.quantity, s.name, s.unit_name)
}

fn missing_message(columns: &[Column]) -> String {
    let list: Vec<String> = columns
        .iter()
        .map(|c| {
            let s = c.spec();
            format!("'{}' ({}, {})", s.name, s.quantity, s.unit)
        })
        .collect();
    let plural = if columns.len() == 1 { "" } else { "s" };
    format!("missing required column{plural} {}", list.join(", "))
}

const NUMBER_FORM: &str = "numbers must be plain decimals such as 12.5 or 1.5e-3";

fn number_message(column: Column, text: &str, issue: NumberIssue) -> String {
    match issue {
        NumberIssue::NotANumber => format!("\"{text}\" is not a number; {NUMBER_FORM}"),
        NumberIssue::NotFinite if column.is_required() => {
            format!(
                "\"{text}\" is not a finite number; {NUMBER_FORM}, and this required column needs a value in every row"
            )
        }
        NumberIssue::NotFinite => {
            format!("\"{text}\" is not a finite number; {NUMBER_FORM}; leave the cell empty if it was not measured")
        }
        NumberIssue::Hexadecimal => format!("\"{text}\" is a hexadecimal number; {NUMBER_FORM}"),
        NumberIssue::IncompleteExponent => {
            format!("\"{text}\" has an exponent without digits (truncated line?); {NUMBER_FORM}")
        }
        NumberIssue::UnitInCell => {
            let unit = column.spec().unit;
            let unit = if unit.is_empty() { String::new() } else { format!(" (in {unit})") };
            format!("\"{text}\" has a unit in the cell; the unit belongs in the column name, the cell holds only the number{unit}")
        }
        NumberIssue::Overflow => format!("\"{text}\" is too large for a 64-bit float"),
    }
}
