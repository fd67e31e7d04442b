//! Demo scripts: what `lucent demo --script FILE` does at which tick, for tests and recordings.
//!
//! One command per line, `TICK COMMAND ARGS...`; `#` starts a comment, blank lines are ignored,
//! ticks never decrease. A tick is a presented frame, or, while the window is minimized (nothing
//! can be presented), one 16 ms wait, so a script that minimizes the window keeps running. The
//! commands are listed in [`Command`] and in the README's "Demo" section.

use std::path::{Path, PathBuf};

use crate::{LucentError, Result};

/// Largest script file accepted.
const MAX_SCRIPT_BYTES: u64 = 1 << 20;

/// One scripted action.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `resize W H`: ask the window system for this inner size; `resize 0 0` (either side 0)
    /// minimizes: the demo enters the state a zero-sized window puts it in, whether or not the
    /// window system can show a zero-sized window (X servers cannot).
    Resize(u32, u32),
    /// `technique NAME`: switch to a technique of `Technique::all`.
    Technique(String),
    /// `orbit DX DY`: turn the camera around its target by DX degrees (yaw) and DY (pitch).
    Orbit(f32, f32),
    /// `zoom F`: multiply the camera's distance to its target by F (> 0).
    Zoom(f32),
    /// `pan DX DY`: move camera and target in the view plane by DX, DY times the distance.
    Pan(f32, f32),
    /// `fly F R U`: move camera and target forward, right and up by that many world units.
    Fly(f32, f32, f32),
    /// `reset`: the scene's own camera again.
    Reset,
    /// `key NAME`: press a key (its name as the key list gives it, e.g. `F1`, `T`, `2`, `+`).
    Key(String),
    /// `screenshot FILE`: write what the window shows (the frame or a comparison view, without
    /// the panel) as PNG.
    Screenshot(PathBuf),
    /// `quit`: end the demo (exit 0).
    Quit,
}

/// A parsed script: commands sorted by tick.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    /// `(tick, command)` in file order (ticks non-decreasing).
    pub steps: Vec<(u64, Command)>,
    next: usize,
}

impl Script {
    /// Reads and parses a script file.
    pub fn load(path: &Path) -> Result<Self> {
        // A regular file read with a cap (a FIFO or device is refused, never read forever).
        let bytes = crate::files::read_capped(path, MAX_SCRIPT_BYTES, "demo script")
            .map_err(|e| LucentError::file(path, format!("cannot read script: {e}")))?;
        let text = String::from_utf8(bytes)
            .map_err(|_| LucentError::file(path, "cannot read script: not UTF-8 text"))?;
        Self::parse(&text).map_err(|e| LucentError::file(path, e))
    }

    /// Parses script text; errors name the line.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        let mut steps = Vec::new();
        let mut last_tick = 0;
        for (index, raw) in text.lines().enumerate() {
            let line_no = index + 1;
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let fail = |m: String| format!("line {line_no}: {m} (in '{}')", raw.trim());
            let mut words = line.split_whitespace();
            let tick_word = words.next().unwrap_or("");
            let tick: u64 = tick_word
                .parse()
                .map_err(|_| fail(format!("'{tick_word}' is not a tick number")))?;
            if tick < last_tick {
                return Err(fail(format!(
                    "tick {tick} comes after tick {last_tick}; ticks must not decrease"
                )));
            }
            last_tick = tick;
            let name = words
                .next()
                .ok_or_else(|| fail("a command must follow the tick".into()))?;
            let args: Vec<&str> = words.collect();
            let command = parse_command(name, &args).map_err(fail)?;
            steps.push((tick, command));
        }
        Ok(Self { steps, next: 0 })
    }

    /// The commands due at `tick` (every not yet taken command with a tick <= `tick`).
    pub fn due(&mut self, tick: u64) -> Vec<Command> {
        let mut due = Vec::new();
        while let Some((t, command)) = self.steps.get(self.next) {
            if *t > tick {
                break;
            }
            due.push(command.clone());
            self.next += 1;
        }
        due
    }

    /// Whether every command has been taken.
    pub fn finished(&self) -> bool {
        self.next >= self.steps.len()
    }
}

fn parse_command(name: &str, args: &[&str]) -> std::result::Result<Command, String> {
    let count = |n: usize| {
        if args.len() == n {
            Ok(())
        } else {
            Err(format!(
                "'{name}' takes {n} argument(s), got {}",
                args.len()
            ))
        }
    };
    // Finite numbers only: a NaN angle or distance would poison the camera for the whole run.
    let number = |s: &str| -> std::result::Result<f32, String> {
        s.parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{s}' is not a finite number"))
    };
    let size = |s: &str| -> std::result::Result<u32, String> {
        s.parse::<u32>()
            .ok()
            .filter(|&v| v <= 16384)
            .ok_or_else(|| format!("'{s}' is not a size between 0 and 16384"))
    };
    match name {
        "resize" => {
            count(2)?;
            Ok(Command::Resize(size(args[0])?, size(args[1])?))
        }
        "technique" => {
            count(1)?;
            // Checked here, so a typo fails before the window opens, with its line.
            crate::frame::Technique::parse(args[0]).map_err(|e| e.to_string())?;
            Ok(Command::Technique(args[0].to_string()))
        }
        "orbit" => {
            count(2)?;
            Ok(Command::Orbit(number(args[0])?, number(args[1])?))
        }
        "zoom" => {
            count(1)?;
            let f = number(args[0])?;
            if f <= 0.0 {
                return Err(format!("zoom factor {f} must be > 0"));
            }
            Ok(Command::Zoom(f))
        }
        "pan" => {
            count(2)?;
            Ok(Command::Pan(number(args[0])?, number(args[1])?))
        }
        "fly" => {
            count(3)?;
            Ok(Command::Fly(
                number(args[0])?,
                number(args[1])?,
                number(args[2])?,
            ))
        }
        "reset" => count(0).map(|()| Command::Reset),
        "key" => {
            count(1)?;
            if super::controls::action_named(args[0]).is_none() {
                return Err(format!(
                    "unknown key '{}'; known: {}",
                    args[0],
                    super::controls::KEYS
                        .iter()
                        .map(|k| k.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            Ok(Command::Key(args[0].to_string()))
        }
        "screenshot" => {
            count(1)?;
            Ok(Command::Screenshot(PathBuf::from(args[0])))
        }
        "quit" => count(0).map(|()| Command::Quit),
        other => Err(format!(
            "unknown command '{other}'; known: resize, technique, orbit, zoom, pan, fly, reset, \
             key, screenshot, quit"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_command_and_hands_them_out_by_tick() {
        let mut script = Script::parse(
            "# a comment\n\n5 resize 640 480\n5 technique control # trailing\n10 orbit 30 -10\n\
             12 zoom 0.5\n12 pan 0.1 0\n13 fly 1 0 -1\n20 reset\n20 key F1\n30 screenshot a.png\n40 quit\n",
        )
        .unwrap();
        assert_eq!(script.steps.len(), 10);
        assert!(script.due(4).is_empty());
        assert_eq!(
            script.due(5),
            vec![
                Command::Resize(640, 480),
                Command::Technique("control".into())
            ]
        );
        // A tick skipped (e.g. two commands due while nothing was presented) still hands out all.
        assert_eq!(script.due(19).len(), 4);
        assert_eq!(script.due(35).len(), 3);
        assert!(!script.finished());
        assert_eq!(script.due(40), vec![Command::Quit]);
        assert!(script.finished());
    }

    #[test]
    fn rejects_bad_lines_with_their_number() {
        for (text, wanted) in [
            ("x resize 1 2", "line 1: 'x' is not a tick"),
            ("5 resize 1", "takes 2 argument"),
            ("5 resize 1 99999", "between 0 and 16384"),
            ("5 orbit nan 0", "not a finite number"),
            ("5 zoom 0", "must be > 0"),
            ("\n5 dance", "line 2: unknown command 'dance'"),
            ("9 reset\n3 reset", "ticks must not decrease"),
            ("7", "a command must follow"),
            (
                "1 reset\n2 key Nope",
                "line 2: unknown key 'Nope'; known: F1",
            ),
            ("3 technique lbbb", "line 1: unknown technique 'lbbb'"),
        ] {
            let err = Script::parse(text).unwrap_err();
            assert!(err.contains(wanted), "{text:?}: {err}");
        }
    }
}
