//! Where a key is in a scene file's text: a path of keys and places in arrays, followed
//! through the TOML as parsed with its spans, gives the line and column.

use toml::de::{DeTable, DeValue};

/// One step into a scene file: a key of a table, or a place in an array.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum Step {
    Key(&'static str),
    At(usize),
}

/// Line and column (1-based) of byte `offset` in `text`.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

/// Line and column of `path` in `text`: of its last key where the path ends in one, else
/// of the value it reaches; of the deepest step the text has where it stops short (a key
/// left to its default is at its table).
pub(super) fn locate(text: &str, path: &[Step]) -> (usize, usize) {
    let Ok(root) = DeTable::parse(text) else {
        return (1, 1);
    };
    let mut offset = root.span().start;
    let mut here: Option<&DeValue<'_>> = None;
    let mut table = Some(root.get_ref());
    for step in path {
        let next = match (step, table, here) {
            (Step::Key(key), Some(t), _) => {
                t.iter().find(|(k, _)| k.get_ref() == key).map(|(k, v)| {
                    offset = k.span().start;
                    v
                })
            }
            (Step::At(i), _, Some(DeValue::Array(items))) => {
                items.get(*i).inspect(|v| offset = v.span().start)
            }
            _ => None,
        };
        let Some(value) = next else {
            break;
        };
        here = Some(value.get_ref());
        table = match value.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => None,
        };
    }
    line_column(text, offset)
}

/// Byte offset of the first `key = …` at or after `offset` (for errors the parser reports
/// at the table that holds the key).
pub(super) fn find_key(text: &str, offset: usize, key: &str) -> Option<usize> {
    let offset = offset.min(text.len());
    text[offset..]
        .match_indices(key)
        .map(|(at, _)| at + offset)
        .find(|&at| {
            // A whole key: not the tail of a longer one, and followed by `=`.
            let whole = text[..at]
                .chars()
                .next_back()
                .is_none_or(|c| !(c.is_alphanumeric() || c == '_' || c == '-'));
            whole && text[at + key.len()..].trim_start().starts_with('=')
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Repeated keys are told apart by where they are: the second keyframe's `time` of the
    /// second obstacle, a key of an inline table, a key left out (at its table).
    #[test]
    fn a_path_finds_its_own_key_among_repeated_ones() {
        let text = "\
name = \"x\"
[[effects]]
type = \"obstacle\"
keyframes = [ { time = 0.0 }, { time = 1.0 } ]

[[effects]]
type = \"obstacle\"
keyframes = [ { time = 0.0 },
              { time = 2.0, ease = \"smooth\" } ]
[cloth]
grid = { quads = 4, size = 1.0 }
";
        use Step::{At, Key};
        let path = [Key("effects"), At(1), Key("keyframes"), At(1), Key("time")];
        assert_eq!(locate(text, &path), (9, 17));
        assert_eq!(
            locate(text, &[Key("effects"), At(0), Key("keyframes")]),
            (4, 1)
        );
        assert_eq!(
            locate(text, &[Key("cloth"), Key("grid"), Key("size")]),
            (11, 21)
        );
        // Not written: the table it would be in.
        assert_eq!(
            locate(text, &[Key("effects"), At(1), Key("friction")]),
            (6, 1)
        );
    }
}
