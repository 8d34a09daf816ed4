//! Shared by `fuzz_scene.rs`, `fuzz_gltf.rs` and `fuzz_save.rs`: structure-aware mutations of valid seed files,
//! a watchdog that runs each input on a worker thread under a time limit (a hang fails the test
//! instead of stalling it), the case count from `SNOWPRINT_FUZZ_CASES`, and the process's peak RSS.
//!
//! The fuzzers run on the stable toolchain with proptest: a failing input is shrunk and printed.

#![allow(dead_code)]

use std::cell::RefCell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::time::Duration;

use proptest::prelude::*;

/// Cases of one fuzz test: `SNOWPRINT_FUZZ_CASES`, or `default` (a bounded run of a few seconds
/// for `make test`).
pub fn cases(default: u32) -> u32 {
    match std::env::var("SNOWPRINT_FUZZ_CASES") {
        Ok(v) => v
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("SNOWPRINT_FUZZ_CASES={v:?} is not a whole number")),
        Err(_) => default,
    }
}

/// A proptest configuration for `cases` inputs, shrinking failures, persisting nothing.
pub fn config(cases: u32) -> proptest::test_runner::Config {
    proptest::test_runner::Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 2_000,
        ..proptest::test_runner::Config::default()
    }
}

/// Peak resident set of this process, bytes (`VmHWM` of `/proc/self/status`), where known.
pub fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Peak resident memory of a whole fuzz test process, bytes.
pub const RSS_BOUND: u64 = 1 << 30;

/// Report a run's figures (shown with `--nocapture`) and check the memory bound.
pub fn finish(name: &str, n: u32, start: std::time::Instant) {
    let rss = peak_rss();
    println!(
        "{name}: {n} inputs in {:.1} s, peak RSS {} MiB",
        start.elapsed().as_secs_f64(),
        rss.map_or("unknown".to_owned(), |b| (b >> 20).to_string())
    );
    if let Some(rss) = rss {
        assert!(rss < RSS_BOUND, "peak RSS {rss} bytes is over {RSS_BOUND}");
    }
}

type Job<I, O> = (I, Sender<Result<O, String>>);
type JobChannel<I, O> = (Sender<Job<I, O>>, Receiver<Job<I, O>>);

impl<I: Send + 'static> Watchdog<I, Result<(), String>> {
    /// Run one input as a proptest case: a broken answer, a panic or a hang fails it.
    pub fn check(&self, input: I) -> Result<(), TestCaseError> {
        match self.run(input) {
            Ok(Ok(())) => Ok(()),
            Ok(Err(broken)) => Err(TestCaseError::fail(broken)),
            Err(e) => Err(TestCaseError::fail(e)),
        }
    }
}

/// Runs a function on a worker thread, one input at a time, and fails an input that panics or runs
/// longer than the limit. After a timeout the stuck worker is abandoned and a new one started, so
/// that shrinking can go on.
pub struct Watchdog<I: Send + 'static, O: Send + 'static> {
    f: fn(I) -> O,
    limit: Duration,
    worker: RefCell<Sender<Job<I, O>>>,
}

impl<I: Send + 'static, O: Send + 'static> Watchdog<I, O> {
    /// A watchdog over `f` with a time limit per input.
    pub fn new(f: fn(I) -> O, limit: Duration) -> Self {
        Self {
            f,
            limit,
            worker: RefCell::new(Self::spawn(f)),
        }
    }

    fn spawn(f: fn(I) -> O) -> Sender<Job<I, O>> {
        let (tx, rx): JobChannel<I, O> = channel();
        std::thread::spawn(move || {
            while let Ok((input, reply)) = rx.recv() {
                let out = catch_unwind(AssertUnwindSafe(|| f(input))).map_err(|p| {
                    p.downcast_ref::<String>()
                        .cloned()
                        .or_else(|| p.downcast_ref::<&str>().map(|s| (*s).to_owned()))
                        .unwrap_or_else(|| "a panic without a message".to_owned())
                });
                let _ = reply.send(out);
            }
        });
        tx
    }

    /// Run one input: its result, or an error naming the panic or the timeout.
    pub fn run(&self, input: I) -> Result<O, String> {
        let (reply_tx, reply_rx) = channel();
        if self.worker.borrow().send((input, reply_tx)).is_err() {
            return Err("the worker thread is gone".into());
        }
        match reply_rx.recv_timeout(self.limit) {
            Ok(Ok(out)) => Ok(out),
            Ok(Err(panic)) => Err(format!("panicked: {panic}")),
            Err(RecvTimeoutError::Timeout) => {
                *self.worker.borrow_mut() = Self::spawn(self.f);
                Err(format!("did not finish within {:?} (a hang)", self.limit))
            }
            Err(RecvTimeoutError::Disconnected) => Err("the worker thread died".into()),
        }
    }
}

/// One edit of a seed file. Positions are taken modulo the current length.
#[derive(Clone, Debug)]
pub enum Edit {
    /// Flip one bit of one byte.
    FlipBit { at: usize, bit: u8 },
    /// Replace one byte.
    SetByte { at: usize, byte: u8 },
    /// Insert bytes.
    Insert { at: usize, bytes: Vec<u8> },
    /// Insert a token of the format's dictionary.
    Token { at: usize, token: usize },
    /// Delete a run of bytes.
    Delete { at: usize, len: usize },
    /// Copy a run of bytes elsewhere, `times` times (grows inputs: many keys, deep nesting).
    Duplicate {
        from: usize,
        len: usize,
        at: usize,
        times: usize,
    },
    /// Copy line `line` of the other seed in before line `at` (a splice of two valid files).
    SpliceLine { line: usize, at: usize },
    /// Delete line `line`.
    DeleteLine { line: usize },
    /// Swap two lines.
    SwapLines { a: usize, b: usize },
}

/// Any edit; `tokens` is the size of the format's dictionary.
pub fn edit(tokens: usize) -> impl Strategy<Value = Edit> {
    let pos = any::<usize>();
    prop_oneof![
        (pos, 0u8..8).prop_map(|(at, bit)| Edit::FlipBit { at, bit }),
        (pos, any::<u8>()).prop_map(|(at, byte)| Edit::SetByte { at, byte }),
        (pos, prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(at, bytes)| Edit::Insert { at, bytes }),
        (pos, 0..tokens).prop_map(|(at, token)| Edit::Token { at, token }),
        (pos, 1usize..64).prop_map(|(at, len)| Edit::Delete { at, len }),
        (pos, 1usize..256, pos, 1usize..64).prop_map(|(from, len, at, times)| {
            Edit::Duplicate {
                from,
                len,
                at,
                times,
            }
        }),
        (pos, pos).prop_map(|(line, at)| Edit::SpliceLine { line, at }),
        pos.prop_map(|line| Edit::DeleteLine { line }),
        (pos, pos).prop_map(|(a, b)| Edit::SwapLines { a, b }),
    ]
}

fn lines(bytes: &[u8]) -> Vec<Vec<u8>> {
    bytes
        .split_inclusive(|&b| b == b'\n')
        .map(<[u8]>::to_vec)
        .collect()
}

/// Apply edits to `seed`; `other` is the seed spliced from; `dictionary` the format's tokens.
pub fn apply(seed: &[u8], other: &[u8], edits: &[Edit], dictionary: &[&str]) -> Vec<u8> {
    let mut out = seed.to_vec();
    for e in edits {
        let n = out.len();
        let at = |p: usize| if n == 0 { 0 } else { p % (n + 1) };
        match e {
            Edit::FlipBit { at: p, bit } if n > 0 => out[p % n] ^= 1 << bit,
            Edit::SetByte { at: p, byte } if n > 0 => out[p % n] = *byte,
            Edit::Insert { at: p, bytes } => {
                let i = at(*p);
                out.splice(i..i, bytes.iter().copied());
            }
            Edit::Token { at: p, token } => {
                let i = at(*p);
                let t = dictionary[token % dictionary.len()].as_bytes();
                out.splice(i..i, t.iter().copied());
            }
            Edit::Delete { at: p, len } if n > 0 => {
                let i = p % n;
                out.drain(i..(i + len).min(n));
            }
            Edit::Duplicate {
                from,
                len,
                at: p,
                times,
            } if n > 0 => {
                let i = from % n;
                let piece = out[i..(i + len).min(n)].to_vec();
                let j = at(*p);
                let copies: Vec<u8> = piece
                    .iter()
                    .copied()
                    .cycle()
                    .take(piece.len() * times)
                    .collect();
                out.splice(j..j, copies);
            }
            Edit::SpliceLine { line, at: p } => {
                let theirs = lines(other);
                let mut ours = lines(&out);
                if !theirs.is_empty() {
                    let l = theirs[line % theirs.len()].clone();
                    let j = p % (ours.len() + 1);
                    ours.insert(j, l);
                    out = ours.concat();
                }
            }
            Edit::DeleteLine { line } => {
                let mut ours = lines(&out);
                if !ours.is_empty() {
                    let k = line % ours.len();
                    ours.remove(k);
                    out = ours.concat();
                }
            }
            Edit::SwapLines { a, b } => {
                let mut ours = lines(&out);
                if !ours.is_empty() {
                    let k = ours.len();
                    ours.swap(a % k, b % k);
                    out = ours.concat();
                }
            }
            _ => {}
        }
    }
    out
}

/// Numbers that find edges: zero, tiny, huge, beyond f32, non-finite, negative, and plain ones.
pub fn edgy_number() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("0".to_owned()),
        Just("-0.0".to_owned()),
        Just("1e-45".to_owned()),
        Just("1e-38".to_owned()),
        Just("3e38".to_owned()),
        Just("3.5e38".to_owned()),
        Just("1e39".to_owned()),
        Just("1e300".to_owned()),
        Just("nan".to_owned()),
        Just("inf".to_owned()),
        Just("-inf".to_owned()),
        Just("9223372036854775807".to_owned()),
        Just("-9223372036854775808".to_owned()),
        (-1.0e6f64..1.0e6).prop_map(|v| format!("{v:?}")),
        (-10.0f64..10.0).prop_map(|v| format!("{v:?}")),
        (0i64..1_000_000).prop_map(|v| v.to_string()),
    ]
}

/// Standard base64 with padding.
pub fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ABC[((n >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A unit tetrahedron wound outward: 4 float positions (48 bytes) then 12 u16 indices (24 bytes).
pub fn tetrahedron_bytes() -> Vec<u8> {
    let positions: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let indices: [u16; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
    let mut bytes = Vec::new();
    for c in positions.iter().flatten() {
        bytes.extend_from_slice(&c.to_le_bytes());
    }
    for i in indices {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes
}

/// glTF JSON of the tetrahedron with the given `nodes` array and scene roots; its buffer is the
/// tetrahedron's 72 bytes at `uri` (`None`: no uri, the GLB's binary chunk).
pub fn tetrahedron_json(nodes: &str, roots: &str, uri: Option<&str>) -> String {
    let uri = uri.map_or(String::new(), |u| format!(r#", "uri": "{u}""#));
    format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scene": 0,
  "scenes": [ {{ "nodes": {roots} }} ],
  "nodes": {nodes},
  "meshes": [ {{ "primitives": [ {{ "attributes": {{ "POSITION": 0 }}, "indices": 1 }} ] }} ],
  "buffers": [ {{ "byteLength": 72{uri} }} ],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 24, "target": 34963 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0] }},
    {{ "bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR" }}
  ]
}}
"#
    )
}

/// The tetrahedron in one node moved up by 1 m, its buffer embedded as a data: URI.
pub fn tetrahedron_gltf() -> String {
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64(&tetrahedron_bytes())
    );
    tetrahedron_json(
        r#"[ { "mesh": 0, "translation": [0.0, 1.0, 0.0] } ]"#,
        "[0]",
        Some(&uri),
    )
}

/// A GLB container: the JSON chunk (padded with spaces) and the binary chunk (padded with zeros).
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// The tetrahedron as GLB: one node, buffer 0 in the binary chunk.
pub fn tetrahedron_glb() -> Vec<u8> {
    glb(
        &tetrahedron_json(r#"[ { "mesh": 0 } ]"#, "[0]", None),
        &tetrahedron_bytes(),
    )
}

/// A fresh folder under the system's temporary folder.
pub fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "snowprint-{tag}-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0)
    ));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}
