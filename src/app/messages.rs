//! The messages the window shows in its status bar.

/// How serious a status message is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    Info,
    Warning,
    Error,
}

/// A message shown in the status area.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub level: Level,
    pub text: String,
}

/// How the status area's tally of forced pairs begins.
const FORCED: &str = "self-contact: prescribed motion (a grab, pins or a handle) forced";

/// The status message for `total` pairs of the cloth forced together by prescribed motion
/// since the simulation began. Where `last`, the latest message, is that tally already, it
/// is updated in place and `None` returned: a drag through the cloth forces pairs frame
/// after frame, and the status area shows one count going up, not a line a frame.
pub fn forced_pairs(last: Option<&mut Message>, total: u64) -> Option<Message> {
    let text = format!("{FORCED} {total} pairs of the cloth together: it may cross itself there");
    match last {
        Some(last) if last.text.starts_with(FORCED) => {
            last.text = text;
            None
        }
        _ => Some(Message {
            level: Level::Warning,
            text,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forced_pairs_count_up_in_one_message() {
        let first = forced_pairs(None, 3).expect("a new message");
        assert_eq!(first.level, Level::Warning);
        assert!(first.text.contains("forced 3 pairs"), "{}", first.text);
        let mut shown = vec![first];
        assert_eq!(forced_pairs(shown.last_mut(), 10), None);
        assert!(
            shown[0].text.contains("forced 10 pairs"),
            "{}",
            shown[0].text
        );
        // After another message, the tally starts a line of its own.
        shown.push(Message {
            level: Level::Info,
            text: "stability guard: recovered".into(),
        });
        let again = forced_pairs(shown.last_mut(), 12).expect("a new message");
        assert!(again.text.contains("forced 12 pairs"));
        assert_eq!(shown.len(), 2);
    }
}
