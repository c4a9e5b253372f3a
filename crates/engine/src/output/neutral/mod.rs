//! Text from other people's files (case keys, commits, reasons, paths, program output) made
//! harmless for the syntax it is written into: one module per output syntax, used by every
//! writer of that syntax, so that a writer cannot forget a case the others handle.
//!
//! - [`control`]: control characters (C0, DEL, C1, ESC among them) as visible escapes, for
//!   terminals, and inside the other syntaxes where a raw one would end a line or a cell;
//! - [`markdown`]: code spans that nothing inside can close, and text with no raw HTML, link
//!   or emphasis in it (REPORT.md, `summary.md`, the gate's and the history's summaries);
//! - [`url`]: which links an HTML page may make clickable (http, https, mailto, relative
//!   paths and fragments; never `javascript:` or `data:`);
//! - [`spreadsheet`]: text cells of CSV and JSON lines that a spreadsheet would not run as a
//!   formula.

pub mod control;
pub mod markdown;
pub mod spreadsheet;
pub mod url;
