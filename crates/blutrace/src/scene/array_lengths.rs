//! Arrays written longer than their key takes. serde reads a fixed-size array such as a
//! point (`[f64; 3]`) from its first elements and, through the `toml` crate, drops the
//! rest without a word, so `center = [1.0, 2.0, 3.0, 99.0]` would load as
//! `[1.0, 2.0, 3.0]`. The scene file as written is compared with the scene file as read
//! (serialized back): an array whose length differs is an error naming its key.
//!
//! ```toml
//! [[sources]]
//! center = [0.0, 0.0, 0.5, 99.0]   # error: sources[0].center has 4 numbers, takes 3
//! ```

use super::config::SceneFile;
use crate::spec_check::Ctx;
use anyhow::Result;
use toml::Value;

/// Refuse an array of `written` (the scene file as written) that `file` (as read) holds
/// with another length.
pub(super) fn check(ctx: &Ctx, written: &Value, file: &SceneFile) -> Result<()> {
    let Ok(read) = Value::try_from(file) else {
        return Ok(()); // nothing to compare with; the loader reports what it cannot write
    };
    match first_difference(written, &read, "") {
        Some((at, had, takes)) => Err(ctx.err(
            &at,
            format!("has {had} elements, but it takes {takes}: remove the extra ones"),
        )),
        None => Ok(()),
    }
}

/// The first array (its key path, written and read lengths) whose lengths differ.
fn first_difference(written: &Value, read: &Value, at: &str) -> Option<(String, usize, usize)> {
    match (written, read) {
        (Value::Table(w), Value::Table(r)) => w.iter().find_map(|(k, v)| {
            let key = if at.is_empty() {
                k.clone()
            } else {
                format!("{at}.{k}")
            };
            first_difference(v, r.get(k)?, &key)
        }),
        (Value::Array(w), Value::Array(r)) if w.len() != r.len() => {
            Some((at.to_owned(), w.len(), r.len()))
        }
        (Value::Array(w), Value::Array(r)) => w
            .iter()
            .zip(r)
            .enumerate()
            .find_map(|(i, (a, b))| first_difference(a, b, &format!("{at}[{i}]"))),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_longer_array_than_read_is_found_with_its_key() {
        let written: Value = toml::from_str("[[s]]\nc = [1.0, 2.0, 3.0, 4.0]\n").unwrap();
        let read: Value = toml::from_str("[[s]]\nc = [1.0, 2.0, 3.0]\n").unwrap();
        assert_eq!(
            first_difference(&written, &read, ""),
            Some(("s[0].c".into(), 4, 3))
        );
        assert_eq!(first_difference(&read, &read, ""), None);
        let nested: Value = toml::from_str("t = [[1.0, 2.0], [3.0, 4.0, 5.0]]").unwrap();
        let nested_read: Value = toml::from_str("t = [[1.0, 2.0], [3.0, 4.0]]").unwrap();
        assert_eq!(
            first_difference(&nested, &nested_read, ""),
            Some(("t[1]".into(), 3, 2))
        );
    }
}
