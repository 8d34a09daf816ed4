//! Output sets written all or nothing: a reader of an output folder sees the whole set of the last
//! finished run or the whole set of the run before, never a mix and never a half-written file.
//!
//! Layout of an output folder `DIR` holding the set `KEY` (`dump`, `demo`, `report-NAME`, ...):
//!
//! ```text
//! DIR/.snowprint-KEY-partial-PID/      the set being written by the run PID (staging)
//! DIR/.snowprint-KEY-set-PID-NANOS/    a finished set (a generation), never changed again
//! DIR/.snowprint-KEY-current           symlink -> the generation now published
//! DIR/roof.png                         symlink -> .snowprint-KEY-current/roof.png
//! ```
//!
//! A run writes into its staging folder, renames it to a generation (one `rename(2)` of a
//! folder), then replaces the `current` link with a new link to it (another `rename(2)`, which on
//! Linux swaps the link atomically). The per-file links never change target, so every name in the
//! folder switches to the new set at that one instant. The generation published before stays
//! until the next run starts, so a reader that resolved `current` once (`readlink`) keeps reading
//! one set while a run publishes. Staging folders of runs that died (their PID is not alive) and
//! generations that are no longer current are removed when the next run prepares the folder.
//!
//! Every check a folder needs (a file in the way, no permission, a missing parent) happens in
//! [`OutputSet::prepare`], which the commands call before their first frame.

use std::path::{Path, PathBuf};

/// Prefix of every entry this module creates in an output folder.
const PREFIX: &str = ".snowprint-";

/// A set of output files being written into a staging folder; published with
/// [`OutputSet::publish`], or removed on drop.
pub struct OutputSet {
    dir: PathBuf,
    key: String,
    staging: PathBuf,
    names: Vec<String>,
    /// Regular files left by versions before output sets that a new set replaces as a whole.
    legacy: fn(&str) -> bool,
    published: bool,
}

impl OutputSet {
    /// Check `dir` (named `what` in messages, such as `--dump out`), create it and its parents,
    /// clean what dead runs left there for `key`, and open a staging folder for this run.
    pub fn prepare(dir: &Path, key: &str, what: &str) -> Result<Self, String> {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(meta) = std::fs::metadata(dir) {
            if !meta.is_dir() {
                return Err(format!(
                    "{what}: {} is a file, not a folder; give the path of a folder (it is created if missing)",
                    dir.display()
                ));
            }
        } else {
            // A file somewhere along the path makes create_dir_all fail with a vague error: name it.
            for a in dir.ancestors().skip(1) {
                if let Ok(meta) = std::fs::metadata(a)
                    && !meta.is_dir()
                {
                    return Err(format!(
                        "{what}: {} is a file, so {} cannot be created inside it; give another path",
                        a.display(),
                        dir.display()
                    ));
                }
            }
        }
        std::fs::create_dir_all(dir).map_err(|e| {
            format!(
                "{what}: the folder {} cannot be created ({e}); give a path you can write to",
                dir.display()
            )
        })?;
        clean(dir, key);
        let staging = dir.join(format!("{PREFIX}{key}-partial-{}", std::process::id()));
        if staging.exists() {
            let _ = std::fs::remove_dir_all(&staging);
        }
        std::fs::create_dir(&staging).map_err(|e| {
            format!(
                "{what}: cannot write into {} ({e}); give a folder you can write to",
                dir.display()
            )
        })?;
        Ok(Self {
            dir: dir.to_owned(),
            key: key.to_owned(),
            staging,
            names: Vec::new(),
            legacy: |_| false,
            published: false,
        })
    }

    /// Also remove regular files of the folder that `legacy` recognises (outputs of versions before
    /// output sets) when the set is published.
    pub fn with_legacy(mut self, legacy: fn(&str) -> bool) -> Self {
        self.legacy = legacy;
        self
    }

    /// The staging path of an output file `name` (a plain file name), recorded as part of the set.
    pub fn path(&mut self, name: &str) -> PathBuf {
        if !self.names.iter().any(|n| n == name) {
            self.names.push(name.to_owned());
        }
        self.staging.join(name)
    }

    /// Write the whole file `name` of the set: `contents` into its staging path. The set is
    /// published as a whole, so the file needs no temporary name of its own; this is the one place
    /// where the command's outputs are written, and where a failure is turned into one sentence.
    pub fn write(&mut self, name: &str, contents: impl AsRef<[u8]>) -> Result<PathBuf, String> {
        self.write_with(name, |path| std::fs::write(path, contents))
    }

    /// Write the file `name` of the set with `write`, given its staging path (an encoder that
    /// writes its own file, such as an image's `save`); [`OutputSet::write`] for plain bytes.
    pub fn write_with<E: std::fmt::Display>(
        &mut self,
        name: &str,
        write: impl FnOnce(&Path) -> Result<(), E>,
    ) -> Result<PathBuf, String> {
        let path = self.path(name);
        write(&path).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Ok(path)
    }

    /// Drop `name` from the set (a file that turned out not to be made).
    pub fn forget(&mut self, name: &str) {
        self.names.retain(|n| n != name);
    }

    /// The staging folder (for tools that write several files there, such as ffmpeg's input).
    pub fn staging(&self) -> &Path {
        &self.staging
    }

    /// The names of the files in the set so far.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The folder the set is published into.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Refuse a name that is a folder in the output folder (publishing would fail after the run).
    pub fn check_name(&self, name: &str) -> Result<(), String> {
        let p = self.dir.join(name);
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.is_dir() => Err(format!(
                "{} is a folder, but this run writes a file of that name there; move the folder away or choose another output path",
                p.display()
            )),
            _ => Ok(()),
        }
    }

    /// Make the set the one readers see, in one atomic step; then remove the names of the set
    /// before that are not in this one.
    pub fn publish(mut self) -> Result<(), String> {
        let current_name = format!("{PREFIX}{}-current", self.key);
        let current = self.dir.join(&current_name);
        let generation_name = format!(
            "{PREFIX}{}-set-{}-{}",
            self.key,
            std::process::id(),
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos())
        );
        let generation = self.dir.join(&generation_name);
        let io =
            |what: &str, p: &Path, e: std::io::Error| format!("cannot {what} {}: {e}", p.display());
        std::fs::rename(&self.staging, &generation).map_err(|e| io("publish", &generation, e))?;
        self.published = true;
        // Every name links through `current`; a link that is already there stays as it is.
        for name in &self.names {
            let link = self.dir.join(name);
            let target = Path::new(&current_name).join(name);
            if std::fs::read_link(&link).is_ok_and(|t| t == target) {
                continue;
            }
            replace_with_symlink(&self.dir, &target, &link, &self.key)
                .map_err(|e| io("link", &link, e))?;
        }
        let previous = std::fs::read_link(&current).ok();
        replace_with_symlink(&self.dir, Path::new(&generation_name), &current, &self.key)
            .map_err(|e| io("publish", &current, e))?;
        // The new set is what readers see from here on; what follows is tidying.
        if let Some(previous) = previous {
            let old = self.dir.join(previous);
            if let Ok(entries) = std::fs::read_dir(&old) {
                for e in entries.flatten() {
                    let name = e.file_name().to_string_lossy().into_owned();
                    if !self.names.contains(&name) {
                        remove_our_link(&self.dir, &current_name, &name);
                    }
                }
            }
        }
        if let Ok(entries) = std::fs::read_dir(&self.dir) {
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                if (self.legacy)(&name)
                    && !self.names.contains(&name)
                    && e.file_type().is_ok_and(|t| t.is_file())
                {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        if !self.published {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// Point `link` at `target` atomically: a new link under a temporary name, renamed over `link`.
fn replace_with_symlink(dir: &Path, target: &Path, link: &Path, key: &str) -> std::io::Result<()> {
    let tmp = dir.join(format!("{PREFIX}{key}-link-{}", std::process::id()));
    let _ = std::fs::remove_file(&tmp);
    symlink(target, &tmp)?;
    std::fs::rename(&tmp, link).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

#[cfg(unix)]
fn symlink(target: &Path, link: &Path) -> std::io::Result<()> {
    std::os::unix::fs::symlink(target, link)
}

#[cfg(not(unix))]
fn symlink(_target: &Path, _link: &Path) -> std::io::Result<()> {
    Err(std::io::Error::new(
        std::io::ErrorKind::Unsupported,
        "output sets need symbolic links (Unix)",
    ))
}

/// Remove `DIR/name` if it is one of our links through `current_name`.
fn remove_our_link(dir: &Path, current_name: &str, name: &str) {
    let link = dir.join(name);
    if std::fs::read_link(&link).is_ok_and(|t| t == Path::new(current_name).join(name)) {
        let _ = std::fs::remove_file(&link);
    }
}

/// Whether the process `pid` is alive; `true` when that cannot be known (no `/proc`).
pub fn alive(pid: u32) -> bool {
    if !Path::new("/proc/self").exists() {
        return true;
    }
    Path::new(&format!("/proc/{pid}")).exists()
}

/// The PID at the end of a staging or temporary name of ours (`...-partial-PID`, `...-link-PID`,
/// and the older `.snowprint-partial-PID` / `.snowprint-demo-partial-PID`).
fn dead_runs_entry(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(PREFIX)?;
    let (head, pid) = rest.rsplit_once('-')?;
    if !(head.ends_with("partial") || head.ends_with("-link")) {
        return None;
    }
    pid.parse().ok()
}

/// Remove what runs that died left in `dir`: staging folders and temporary links of dead PIDs
/// (any key), generations of `key` that are not current, and links of `key` whose file the
/// current generation does not have.
fn clean(dir: &Path, key: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let current_name = format!("{PREFIX}{key}-current");
    let current = std::fs::read_link(dir.join(&current_name)).ok();
    let set_prefix = format!("{PREFIX}{key}-set-");
    let me = std::process::id();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if let Some(pid) = dead_runs_entry(&name) {
            // Our own entries belong to other sets this run is writing (a report beside a dump).
            if pid != me && !alive(pid) {
                remove_any(&e.path());
            }
            continue;
        }
        if name.starts_with(&set_prefix) && current.as_deref() != Some(Path::new(&name)) {
            remove_any(&e.path());
            continue;
        }
        if let Ok(target) = std::fs::read_link(e.path())
            && target.starts_with(&current_name)
            && !dir.join(&target).exists()
        {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

fn remove_any(p: &Path) {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => {
            let _ = std::fs::remove_dir_all(p);
        }
        Ok(_) => {
            let _ = std::fs::remove_file(p);
        }
        Err(_) => {}
    }
}

/// A key for the set of a report file: `report-` and the file's stem, letters and digits only.
pub fn report_key(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let clean: String = stem
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .take(64)
        .collect();
    format!("report-{clean}")
}

/// Check before the first frame that a single output file (`--save`) can be written: it is not a
/// folder, its folder exists or can be created, and a file can be made there. The file itself is
/// written later, atomically (a temporary file beside it, then a rename).
pub fn check_file_target(path: &Path, what: &str) -> Result<(), String> {
    let what = format!("{what} {}", path.display());
    if path.is_dir() {
        return Err(format!(
            "{what} is a folder; give a file path such as {}",
            path.join("snow.save").display()
        ));
    }
    if path.file_name().is_none() {
        return Err(format!(
            "{what} names no file; give a file path such as snow.save"
        ));
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    for a in dir.ancestors() {
        if let Ok(meta) = std::fs::metadata(a)
            && !meta.is_dir()
        {
            return Err(format!(
                "{what}: {} is a file, so the save cannot go inside it; give another path",
                a.display()
            ));
        }
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        format!(
            "{what}: the folder {} cannot be created ({e}); give a path you can write to",
            dir.display()
        )
    })?;
    let probe = dir.join(format!("{PREFIX}probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| {
        format!(
            "{what}: cannot write into {} ({e}); give a folder you can write to",
            dir.display()
        )
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("snowprint-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn write_set(dir: &Path, files: &[(&str, &str)]) {
        let mut set = OutputSet::prepare(dir, "dump", "--dump").unwrap();
        for (name, text) in files {
            std::fs::write(set.path(name), text).unwrap();
        }
        set.publish().unwrap();
    }

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| !n.starts_with('.'))
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_second_set_replaces_the_first_as_a_whole() {
        let dir = scratch("replace");
        write_set(&dir, &[("a.json", "1"), ("b.json", "1")]);
        assert_eq!(listing(&dir), ["a.json", "b.json"]);
        std::fs::write(dir.join("notes.txt"), "the user's").unwrap();
        write_set(&dir, &[("a.json", "2"), ("c.json", "2")]);
        assert_eq!(listing(&dir), ["a.json", "c.json", "notes.txt"]);
        assert_eq!(std::fs::read_to_string(dir.join("a.json")).unwrap(), "2");
        assert_eq!(std::fs::read_to_string(dir.join("c.json")).unwrap(), "2");
        // The set before stays readable until the next run starts.
        let hidden: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("-set-"))
            .collect();
        assert_eq!(hidden.len(), 2, "{hidden:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_dropped_set_leaves_the_published_one_and_no_staging() {
        let dir = scratch("drop");
        write_set(&dir, &[("a.json", "1")]);
        {
            let mut set = OutputSet::prepare(&dir, "dump", "--dump").unwrap();
            std::fs::write(set.path("a.json"), "2").unwrap();
        }
        assert_eq!(std::fs::read_to_string(dir.join("a.json")).unwrap(), "1");
        assert!(
            !std::fs::read_dir(&dir).unwrap().any(|e| e
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains("partial"))
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn staging_of_a_dead_run_is_cleaned_and_a_live_one_kept() {
        let dir = scratch("dead");
        std::fs::create_dir_all(dir.join(".snowprint-dump-partial-999999999")).unwrap();
        std::fs::create_dir_all(dir.join(".snowprint-partial-999999998")).unwrap();
        // PID 1 is always alive.
        std::fs::create_dir_all(dir.join(".snowprint-demo-partial-1")).unwrap();
        write_set(&dir, &[("a.json", "1")]);
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("partial"))
            .collect();
        assert_eq!(names, [".snowprint-demo-partial-1"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_file_in_the_way_is_refused_before_anything_is_written() {
        let dir = scratch("file");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("f"), "x").unwrap();
        let e = OutputSet::prepare(&dir.join("f"), "dump", "--dump")
            .err()
            .unwrap();
        assert!(e.contains("is a file, not a folder"), "{e}");
        let e = OutputSet::prepare(&dir.join("f/g/h"), "dump", "--dump")
            .err()
            .unwrap();
        assert!(e.contains("is a file, so"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
