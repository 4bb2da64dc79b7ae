//! The TOML reader's messages in the scene format's words.

/// The TOML reader's message in the scene format's words: Rust's type names
/// (`usize`, `f32`, map, sequence) as TOML speaks of them.
pub(super) fn plain_toml_message(msg: &str) -> String {
    const WORDS: [(&str, &str); 13] = [
        ("expected usize", "expected a whole number of 0 or more"),
        ("expected u64", "expected a whole number of 0 or more"),
        ("expected u32", "expected a whole number of 0 or more"),
        ("expected u16", "expected a whole number of 0 or more"),
        ("expected u8", "expected a whole number of 0 or more"),
        ("expected i64", "expected a whole number"),
        ("expected i32", "expected a whole number"),
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("invalid type: map", "invalid type: a table"),
        ("invalid type: sequence", "invalid type: a list"),
        (
            "expected a sequence",
            "expected a list (or [[name]] tables)",
        ),
        ("expected a map", "expected a table"),
    ];
    WORDS
        .iter()
        .fold(msg.to_string(), |m, (rust, toml)| m.replace(rust, toml))
}

#[cfg(test)]
mod tests {
    #[test]
    fn rust_type_names_become_toml_words() {
        let m = super::plain_toml_message("invalid value: integer `-3`, expected usize");
        assert_eq!(
            m,
            "invalid value: integer `-3`, expected a whole number of 0 or more"
        );
        let m = super::plain_toml_message("invalid type: map, expected a sequence");
        assert_eq!(
            m,
            "invalid type: a table, expected a list (or [[name]] tables)"
        );
        let m = super::plain_toml_message("invalid type: string \"big\", expected f32");
        assert_eq!(m, "invalid type: string \"big\", expected a number");
    }
}
