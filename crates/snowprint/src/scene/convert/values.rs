//! Numbers, vectors and required keys, each checked with the line of its value.

use std::collections::HashMap;
use std::ops::Range;

use crate::error::Result;
use crate::scene::diagnose::Source;
use crate::scene::raw::{Num, Nums, Str};

/// The value as an `f32`, if it stays finite.
pub(super) fn finite(v: f64) -> Option<f32> {
    let v = v as f32;
    v.is_finite().then_some(v)
}

/// A scalar that must be finite and pass `ok`; otherwise `<who> has <key> <value>; <rule>`.
pub(super) fn number(
    src: &Source<'_>,
    v: &Num,
    who: &str,
    key: &str,
    ok: impl Fn(f32) -> bool,
    rule: &str,
) -> Result<f32> {
    match finite(*v.get_ref()) {
        Some(x) if ok(x) => Ok(x),
        _ => Err(src.error(
            &v.span(),
            format!("{who} has {key} {}", src.quote(&v.span())),
            rule,
        )),
    }
}

/// An array of exactly `N` finite numbers that each pass `ok`. `layout` describes the array
/// (such as `[x, y, z] in metres`) for the message about a wrong count.
pub(super) fn vector<const N: usize>(
    src: &Source<'_>,
    v: &Nums,
    who: &str,
    key: &str,
    layout: &str,
    ok: impl Fn(f32) -> bool,
    rule: &str,
) -> Result<[f32; N]> {
    let what = || format!("{who} has {key} {}", src.quote(&v.span()));
    let values = v.get_ref();
    if values.len() != N {
        let count = ["no", "one", "two", "three"]
            .get(N)
            .copied()
            .unwrap_or("more");
        return Err(src.error(
            &v.span(),
            what(),
            format!("{key} needs exactly {count} numbers, {layout}"),
        ));
    }
    let mut out = [0.0; N];
    for (o, &x) in out.iter_mut().zip(values) {
        match finite(x) {
            Some(x) if ok(x) => *o = x,
            _ => return Err(src.error(&v.span(), what(), rule)),
        }
    }
    Ok(out)
}

/// A key that must be there: otherwise `<who> has no <key>; <todo>` on the table's line.
pub(super) fn required<T>(
    src: &Source<'_>,
    table: &Range<usize>,
    v: Option<T>,
    who: &str,
    key: &str,
    todo: &str,
) -> Result<T> {
    v.ok_or_else(|| src.error(table, format!("{who} has no {key}"), todo))
}

/// Record a name (with the byte offset where it is written), refusing one that is already used.
pub(super) fn unique(
    src: &Source<'_>,
    names: &mut HashMap<String, usize>,
    name: &Str,
    kind: &str,
) -> Result<()> {
    if let Some(&first) = names.get(name.get_ref()) {
        return Err(src.error(
            &name.span(),
            format!(
                "{kind} name {:?} is used twice (first at line {})",
                name.get_ref(),
                src.line(first)
            ),
            format!("give every {kind} its own name"),
        ));
    }
    names.insert(name.get_ref().clone(), name.span().start);
    Ok(())
}
