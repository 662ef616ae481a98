//! Values quoted in messages, cut to a readable length.

/// The longest value a message quotes, in characters.
pub const QUOTE_LIMIT: usize = 60;

/// `value` as a message quotes it: whole up to [`QUOTE_LIMIT`] characters, else its start
/// and how long it is, so a huge field does not make a huge message.
///
/// ```
/// assert_eq!(terramesh_io::quote::cut("48.7 7.3"), "48.7 7.3");
/// let long = "9".repeat(5000);
/// assert_eq!(terramesh_io::quote::cut(&long), format!("{}... (5000 characters)", &long[..60]));
/// ```
pub fn cut(value: &str) -> String {
    let n = value.chars().count();
    if n <= QUOTE_LIMIT {
        value.to_string()
    } else {
        let head: String = value.chars().take(QUOTE_LIMIT).collect();
        format!("{head}... ({n} characters)")
    }
}
