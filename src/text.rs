//! Text in messages: user text echoed in them (a name, a token or a value written by a user)
//! cut to a fixed number of characters, so a 100,000-character input cannot flood a log; and
//! byte counts in MiB.

use std::borrow::Cow;

/// `bytes` in MiB with one decimal (KiB for less than a tenth of a MiB).
pub fn format_bytes(bytes: u64) -> String {
    const MIB: f64 = (1 << 20) as f64;
    if bytes > 0 && (bytes as f64) < MIB / 10.0 {
        format!("{:.1} KiB", bytes as f64 / 1024.0)
    } else {
        format!("{:.1} MiB", bytes as f64 / MIB)
    }
}

/// Most characters of user text a message echoes.
pub const MAX_ECHOED_CHARS: usize = 80;

/// `text` cut to at most `max_chars` characters: the first ones, then `...` and how many
/// characters were left out. Text that fits is returned as it is.
pub fn bounded(text: &str, max_chars: usize) -> Cow<'_, str> {
    match text.char_indices().nth(max_chars) {
        None => Cow::Borrowed(text),
        Some(_) => {
            let keep = max_chars.saturating_sub(1);
            let cut = text.char_indices().nth(keep).map_or(text.len(), |(i, _)| i);
            let left = text[cut..].chars().count();
            Cow::Owned(format!("{}... ({left} more characters)", &text[..cut]))
        }
    }
}

/// [`bounded`] at [`MAX_ECHOED_CHARS`].
pub fn echoed(text: &str) -> Cow<'_, str> {
    bounded(text, MAX_ECHOED_CHARS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_text_is_kept_and_long_text_is_cut_with_a_count() {
        assert_eq!(bounded("sun", 3), "sun");
        assert!(matches!(bounded("sun", 3), Cow::Borrowed(_)));
        assert_eq!(bounded("sunset", 3), "su... (4 more characters)");
        let long = "x".repeat(100_000);
        let cut = echoed(&long);
        assert!(cut.chars().count() < 120, "{} characters", cut.chars().count());
        assert!(cut.ends_with("... (99921 more characters)"), "{cut}");
        // Multi-byte characters are cut on their boundaries.
        assert_eq!(bounded("ééééé", 3), "éé... (3 more characters)");
        assert_eq!(bounded("", 0), "");
        assert_eq!(format_bytes(0), "0.0 MiB");
        assert_eq!(format_bytes(3 << 19), "1.5 MiB");
        assert_eq!(format_bytes(2048), "2.0 KiB");
    }
}
