//! Scripted input for `snowprint play --script`: key presses replayed over time, so that a test
//! (or the README's GIF) drives the window without a person at the keyboard.
//!
//! A script is a list of steps, separated by commas or new lines, run one after another. Each step
//! is `KEYS` or `KEYS:DURATION`: `KEYS` is one key name or several joined by `+` (`shift+w`), or
//! `wait` for none; `DURATION` is seconds (`2`, `2s`, `0.5s`) or milliseconds (`500ms`) of the
//! game's clock, 0.1 s when left out (a tap). Keys are held for their step; the actions (slide,
//! fall, throw, tier, view) fire once when their step starts. `#` starts a comment to the end of
//! the line.

/// A key the game reads, from the keyboard or a script.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Key {
    /// Walk away from the camera (W).
    Forward,
    /// Walk towards the camera (S).
    Back,
    /// Walk left (A).
    Left,
    /// Walk right (D).
    Right,
    /// Run while held (Shift).
    Run,
    /// Slide feet first on the back (C).
    Slide,
    /// Fall onto the back (F).
    Fall,
    /// Throw a snowball (Space).
    Throw,
    /// Next snow tier: relief, POM, tessellated (T).
    Tier,
    /// Next debug view (V).
    View,
    /// Orbit the camera left (arrow left).
    OrbitLeft,
    /// Orbit the camera right (arrow right).
    OrbitRight,
    /// Raise the camera (arrow up).
    OrbitUp,
    /// Lower the camera (arrow down).
    OrbitDown,
}

impl Key {
    /// Every key, with the name a script gives it.
    pub const NAMES: [(&'static str, Key); 14] = [
        ("w", Key::Forward),
        ("s", Key::Back),
        ("a", Key::Left),
        ("d", Key::Right),
        ("shift", Key::Run),
        ("c", Key::Slide),
        ("f", Key::Fall),
        ("space", Key::Throw),
        ("t", Key::Tier),
        ("v", Key::View),
        ("left", Key::OrbitLeft),
        ("right", Key::OrbitRight),
        ("up", Key::OrbitUp),
        ("down", Key::OrbitDown),
    ];

    /// Whether the key fires once when pressed (rather than acting while held).
    pub fn is_action(self) -> bool {
        matches!(
            self,
            Key::Slide | Key::Fall | Key::Throw | Key::Tier | Key::View
        )
    }

    fn parse(name: &str) -> Option<Key> {
        let name = name.trim().to_ascii_lowercase();
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, k)| k)
    }
}

/// One step: keys held for a while.
#[derive(Clone, Debug, PartialEq)]
struct Step {
    start: f32,
    duration: f32,
    keys: Vec<Key>,
}

/// A parsed script.
#[derive(Clone, Debug, PartialEq)]
pub struct Script {
    steps: Vec<Step>,
}

/// Seconds a step lasts when it gives no duration.
const TAP: f32 = 0.1;
/// The longest step, seconds: a day of play (a typo such as `w:2e9` is refused, not run).
const LONGEST_STEP: f32 = 86_400.0;

fn parse_duration(text: &str, step: &str) -> Result<f32, String> {
    let t = text.trim().to_ascii_lowercase();
    let (number, scale) = if let Some(ms) = t.strip_suffix("ms") {
        (ms, 1e-3)
    } else if let Some(s) = t.strip_suffix('s') {
        (s, 1.0)
    } else {
        (t.as_str(), 1.0)
    };
    let v: f64 = number.trim().parse().map_err(|_| {
        format!(
            "script step {step:?}: {text:?} is not a duration; give seconds such as 2s or 500ms"
        )
    })?;
    let seconds = v * scale;
    if !seconds.is_finite() || seconds <= 0.0 || seconds > f64::from(LONGEST_STEP) {
        return Err(format!(
            "script step {step:?}: {text:?} is not a duration above 0 and at most a day; give seconds such as 2s or 500ms"
        ));
    }
    Ok(seconds as f32)
}

impl Script {
    /// Parse a script (see the [module documentation](self)); the error names the step and what
    /// to write instead.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut steps = Vec::new();
        let mut start = 0.0f32;
        let names = || {
            Key::NAMES
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", ")
        };
        for line in text.lines() {
            let line = line.split('#').next().unwrap_or("");
            for step in line.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                let (keys_text, duration) = match step.split_once(':') {
                    Some((k, d)) => (k, parse_duration(d, step)?),
                    None => (step, TAP),
                };
                let mut keys = Vec::new();
                if keys_text.trim() != "wait" {
                    for name in keys_text.split('+') {
                        let key = Key::parse(name).ok_or_else(|| {
                            format!(
                                "script step {step:?}: unknown key {:?}; use wait or {}",
                                name.trim(),
                                names()
                            )
                        })?;
                        if !keys.contains(&key) {
                            keys.push(key);
                        }
                    }
                }
                steps.push(Step {
                    start,
                    duration,
                    keys,
                });
                start += duration;
            }
        }
        if steps.is_empty() {
            return Err("the script has no steps; give some such as \"w:2s,space\"".into());
        }
        Ok(Self { steps })
    }

    /// Parse `--script`: the path of a file holding a script, or the script itself.
    pub fn from_arg(arg: &str) -> Result<Self, String> {
        let path = std::path::Path::new(arg);
        if path.is_file() {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("cannot read the script {}: {e}", path.display()))?;
            return Self::parse(&text).map_err(|e| format!("{}: {e}", path.display()));
        }
        Self::parse(arg)
    }

    /// Seconds from the start to the end of the last step.
    pub fn duration(&self) -> f32 {
        self.steps.last().map_or(0.0, |s| s.start + s.duration)
    }

    /// The keys held at time `t`.
    pub fn held(&self, t: f32) -> &[Key] {
        self.steps
            .iter()
            .find(|s| t >= s.start && t < s.start + s.duration)
            .map_or(&[], |s| &s.keys)
    }

    /// The action keys of the steps that start in `(t0, t1]` (and at 0 when `t0` is below 0), in
    /// order.
    pub fn presses(&self, t0: f32, t1: f32) -> Vec<Key> {
        self.steps
            .iter()
            .filter(|s| s.start > t0 && s.start <= t1)
            .flat_map(|s| s.keys.iter().copied().filter(|k| k.is_action()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_run_one_after_another() {
        let s = Script::parse("w:2s, shift+w:500ms\n# a comment\nspace, wait:1").unwrap();
        assert_eq!(s.duration(), 3.6);
        assert_eq!(s.held(0.0), [Key::Forward]);
        assert_eq!(s.held(2.2), [Key::Run, Key::Forward]);
        assert_eq!(s.held(2.55), [Key::Throw]);
        assert!(s.held(3.0).is_empty());
        assert!(s.held(9.0).is_empty());
        // The throw fires once, when its step starts.
        assert_eq!(s.presses(2.4, 2.6), [Key::Throw]);
        assert!(s.presses(2.6, 9.0).is_empty());
        assert!(s.presses(-1.0, 2.4).is_empty(), "held keys are not presses");
        let t = Script::parse("t,v").unwrap();
        assert_eq!(t.presses(-1.0, 0.0), [Key::Tier]);
    }

    #[test]
    fn bad_scripts_are_named() {
        let e = Script::parse("w:2s,jump").unwrap_err();
        assert!(e.contains("\"jump\"") && e.contains("shift"), "{e}");
        let e = Script::parse("w:soon").unwrap_err();
        assert!(e.contains("\"soon\"") && e.contains("500ms"), "{e}");
        for d in ["0", "-1s", "nan", "2e9"] {
            let e = Script::parse(&format!("w:{d}")).unwrap_err();
            assert!(e.contains("above 0"), "{d}: {e}");
        }
        assert!(
            Script::parse(" , # nothing")
                .unwrap_err()
                .contains("no steps")
        );
    }
}
