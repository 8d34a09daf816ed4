//! The hostile corpus: bad scene files (`tests/hostile/NAME.toml`) and bad argument sets
//! (`tests/hostile/args/NAME.args`), each with the one line snowprint must answer
//! (`NAME.expect`). Every case must exit non-zero, answer exactly that line, and print nothing
//! about XDG_RUNTIME_DIR (a probe of the Vulkan loader that is no error of the user's).
//!
//! A scene runs as `snowprint simulate --scene NAME.toml --frames 30 --dump dump` from a scratch
//! folder holding a copy of the corpus. An `.args` file holds one argument a line, run from a
//! scratch folder where `scenes/` is the repository's scene folder; lines starting with `#` are
//! comments, `@file PATH` and `@dir PATH` make a file or a folder there first. The answer is the
//! last line of stderr that starts with `snowprint:` or `error:`. To add a case, add its input
//! and its `.expect`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hostile")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snowprint-hostile-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run snowprint in `cwd` and return (success, the answer line, all of stderr).
fn answer(cwd: &Path, args: &[String]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_snowprint"))
        .args(args)
        .current_dir(cwd)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .env_remove("SNOWPRINT_LOG")
        .output()
        .expect("run snowprint");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let line = err
        .lines()
        .rfind(|l| l.starts_with("snowprint:") || l.starts_with("error:"))
        .unwrap_or("")
        .to_owned();
    (out.status.success(), line, err)
}

fn expected(path: &Path) -> String {
    let p = path.with_extension("expect");
    std::fs::read_to_string(&p)
        .unwrap_or_else(|e| panic!("{} has no {}: {e}", path.display(), p.display()))
        .trim_end()
        .to_owned()
}

fn check(
    name: &str,
    (ok, line, err): (bool, String, String),
    want: &str,
    failures: &mut Vec<String>,
) {
    if ok {
        failures.push(format!("{name}: exited 0\n{err}"));
    } else if line != want {
        failures.push(format!("{name}:\n  want {want}\n  got  {line}\n{err}"));
    } else if err.contains("XDG_RUNTIME_DIR") {
        failures.push(format!("{name}: printed the XDG_RUNTIME_DIR probe\n{err}"));
    }
}

fn cases(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

#[test]
fn every_bad_scene_gets_its_one_line_answer() {
    let work = scratch("scenes");
    let mut failures = Vec::new();
    let scenes = cases(&corpus(), "toml");
    assert!(scenes.len() >= 10, "the corpus lost its scenes");
    for scene in &scenes {
        let name = scene.file_name().unwrap().to_string_lossy().into_owned();
        std::fs::copy(scene, work.join(&name)).unwrap();
        let args: Vec<String> = [
            "simulate", "--scene", &name, "--frames", "30", "--dump", "dump",
        ]
        .map(String::from)
        .to_vec();
        check(&name, answer(&work, &args), &expected(scene), &mut failures);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    let _ = std::fs::remove_dir_all(&work);
}

#[test]
fn every_bad_argument_set_gets_its_one_line_answer() {
    let mut failures = Vec::new();
    let sets = cases(&corpus().join("args"), "args");
    assert!(sets.len() >= 10, "the corpus lost its argument sets");
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for set in &sets {
        let name = set.file_stem().unwrap().to_string_lossy().into_owned();
        let work = scratch(&name);
        std::os::unix::fs::symlink(&scenes, work.join("scenes")).unwrap();
        let mut args = Vec::new();
        for line in std::fs::read_to_string(set).unwrap().lines() {
            if line.starts_with('#') || line.is_empty() {
                continue;
            } else if let Some(p) = line.strip_prefix("@file ") {
                std::fs::write(work.join(p), "not a folder").unwrap();
            } else if let Some(p) = line.strip_prefix("@dir ") {
                std::fs::create_dir_all(work.join(p)).unwrap();
            } else {
                args.push(line.to_owned());
            }
        }
        check(&name, answer(&work, &args), &expected(set), &mut failures);
        let _ = std::fs::remove_dir_all(&work);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
