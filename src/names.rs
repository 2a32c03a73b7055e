//! Names from the user's files (node, material, mesh names, URIs) as they are printed: control
//! characters escaped, so a name cannot move the cursor, recolour or clear the terminal, and
//! cut to a readable length.

/// Longest name printed, in characters; a longer one ends in "...".
pub const MAX_PRINTED_CHARS: usize = 200;

/// `name` with every control character written as an escape (`\u{1b}`, `\n`, ...), cut to
/// [`MAX_PRINTED_CHARS`] characters.
pub fn escaped(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if i == MAX_PRINTED_CHARS {
            out.push_str("...");
            break;
        }
        if needs_escape(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// A whole message for the terminal: every control character but the line breaks escaped,
/// whatever name or file content it quotes.
pub fn for_terminal(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c != '\n' && needs_escape(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Control characters, and the Unicode ones that move or reorder text.
fn needs_escape(c: char) -> bool {
    c.is_control() || matches!(c, '\u{2028}' | '\u{2029}' | '\u{202a}'..='\u{202e}')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_others_kept() {
        assert_eq!(escaped("Water é 水"), "Water é 水");
        assert_eq!(escaped("a\u{1b}[2Jb"), "a\\u{1b}[2Jb");
        assert_eq!(escaped("x\ny\r\t"), "x\\ny\\r\\t");
        assert!(!escaped("\u{7}\u{9b}").chars().any(char::is_control));
        assert_eq!(
            escaped(&"n".repeat(500)).chars().count(),
            MAX_PRINTED_CHARS + 3
        );
        assert_eq!(for_terminal("a\u{1b}]0;x\u{7}\nb"), "a\\u{1b}]0;x\\u{7}\nb");
    }
}
