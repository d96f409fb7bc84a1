//! Structure-aware random edits of valid input files, for the mutation test
//! (`tests/mutation.rs`): the edits a user's tools or a broken download make, which a
//! byte-level fuzzer reaches only slowly.
//!
//! Text edits work on tokens (numbers, words, single punctuation characters, runs of
//! white space): delete, duplicate or swap tokens, replace a number by an extreme or
//! invalid one (`NaN`, `inf`, `1e308`, `-0`, `5e-324`, integers beyond `u64`, ...),
//! flip a sign, swap or duplicate bracketed groups (`[x, y]` points), drop an XML
//! attribute or element, truncate. JSON that parses is also edited as a value (drop a
//! key, reorder, remove or duplicate array elements, replace a number or change a
//! value's type), which keeps it well-formed so that the edit reaches the checks behind
//! the parser. IGES keeps its 80-column records: edits go into the data columns of one
//! Parameter Data record, refitted to 64 columns.

use serde_json::Value;

use super::Lcg;

/// Replacements for a number: extreme, invalid and boundary values.
pub const SPECIAL_NUMBERS: [&str; 26] = [
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e309",
    "1e-320",
    "5e-324",
    "-0",
    "-0.0",
    "0",
    "1",
    "-1",
    "2",
    "13",
    "0.5",
    "1048577",
    "4294967296",
    "9007199254740993",
    "18446744073709551616",
    "-9223372036854775809",
    "99999999999999999999999999999",
    "1e1000000",
];

/// Finite numbers for value-level JSON edits (JSON has no NaN or infinity).
const SPECIAL_VALUES: [f64; 10] = [1e308, -1e308, f64::MAX, 5e-324, -0.0, 0.0, 1e-300, 1e300, -1.0, 0.5];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Number,
    Word,
    Space,
    Punct,
}

#[derive(Debug, Clone, Copy)]
struct Token {
    kind: Kind,
    start: usize,
    end: usize,
}

fn tokens(text: &str) -> Vec<Token> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let digit = |k: usize| k < b.len() && b[k].is_ascii_digit();
    while i < b.len() {
        let start = i;
        let c = b[i];
        let kind = if c.is_ascii_digit() || ((c == b'-' || c == b'+' || c == b'.') && digit(i + 1)) {
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len() && matches!(b[i], b'e' | b'E' | b'D' | b'd') {
                let mut j = i + 1;
                if j < b.len() && (b[j] == b'-' || b[j] == b'+') {
                    j += 1;
                }
                if digit(j) {
                    i = j;
                    while digit(i) {
                        i += 1;
                    }
                }
            }
            Kind::Number
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            Kind::Word
        } else if c.is_ascii_whitespace() {
            while i < b.len() && b[i].is_ascii_whitespace() {
                i += 1;
            }
            Kind::Space
        } else {
            // one character (possibly multi-byte)
            i += text[i..].chars().next().map_or(1, char::len_utf8);
            Kind::Punct
        };
        out.push(Token { kind, start, end: i });
    }
    out
}

fn pick<'a, T>(rng: &mut Lcg, items: &'a [T]) -> Option<&'a T> {
    if items.is_empty() {
        None
    } else {
        Some(&items[rng.below(items.len())])
    }
}

/// Innermost `[...]` groups (no bracket inside), as byte ranges.
fn bracket_groups(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut open = None;
    for (i, c) in text.char_indices() {
        match c {
            '[' => open = Some(i),
            ']' => {
                if let Some(o) = open.take() {
                    out.push((o, i + 1));
                }
            }
            _ => {}
        }
    }
    out
}

/// XML elements `<Name ...>...</Name>` (first closing tag of that name) and self-closed
/// ones, as byte ranges.
fn xml_elements(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (i, _) in text.match_indices('<') {
        let rest = &text[i + 1..];
        let name_len = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(rest.len());
        if name_len == 0 {
            continue;
        }
        let name = &rest[..name_len];
        let Some(gt) = rest.find('>') else { continue };
        if rest[..gt].ends_with('/') {
            out.push((i, i + 1 + gt + 1));
        } else if let Some(k) = rest.find(&format!("</{name}>")) {
            out.push((i, i + 1 + k + name.len() + 3));
        }
    }
    out
}

/// XML attributes ` name="value"`, as byte ranges.
fn xml_attributes(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (q, _) in text.match_indices("=\"") {
        let before = &text[..q];
        let name_start = before.rfind(|c: char| c.is_whitespace()).map_or(0, |k| k);
        if let Some(end) = text[q + 2..].find('"') {
            out.push((name_start, q + 2 + end + 1));
        }
    }
    out
}

/// One token-level edit of `text`; returns its name.
fn edit_text(text: &mut String, rng: &mut Lcg) -> &'static str {
    let toks = tokens(text);
    let solid: Vec<Token> = toks.iter().copied().filter(|t| t.kind != Kind::Space).collect();
    let numbers: Vec<Token> = toks.iter().copied().filter(|t| t.kind == Kind::Number).collect();
    let splice = |text: &mut String, (a, b): (usize, usize), with: &str| text.replace_range(a..b, with);
    let choice = rng.below(12);
    match choice {
        0..=2 => {
            if let Some(t) = pick(rng, &numbers).copied() {
                let s = SPECIAL_NUMBERS[rng.below(SPECIAL_NUMBERS.len())];
                splice(text, (t.start, t.end), s);
                return "replace a number";
            }
        }
        3 => {
            if let Some(t) = pick(rng, &numbers).copied() {
                if text[t.start..].starts_with('-') {
                    splice(text, (t.start, t.start + 1), "");
                } else {
                    text.insert(t.start, '-');
                }
                return "flip a sign";
            }
        }
        4 => {
            if let Some(t) = pick(rng, &solid).copied() {
                splice(text, (t.start, t.end), "");
                return "delete a token";
            }
        }
        5 => {
            if let Some(t) = pick(rng, &solid).copied() {
                let s = text[t.start..t.end].to_string();
                text.insert_str(t.end, &format!(" {s}"));
                return "duplicate a token";
            }
        }
        6 => {
            let (Some(a), Some(b)) = (pick(rng, &solid).copied(), pick(rng, &solid).copied()) else {
                return "nothing";
            };
            let (a, b) = if a.start <= b.start { (a, b) } else { (b, a) };
            if a.end <= b.start {
                let (sa, sb) = (text[a.start..a.end].to_string(), text[b.start..b.end].to_string());
                splice(text, (b.start, b.end), &sa);
                splice(text, (a.start, a.end), &sb);
                return "swap two tokens";
            }
        }
        7 => {
            let groups = bracket_groups(text);
            let (Some(&a), Some(&b)) = (pick(rng, &groups), pick(rng, &groups)) else {
                return "nothing";
            };
            let (a, b) = if a.0 <= b.0 { (a, b) } else { (b, a) };
            if a.1 <= b.0 {
                let (sa, sb) = (text[a.0..a.1].to_string(), text[b.0..b.1].to_string());
                splice(text, b, &sa);
                splice(text, a, &sb);
                return "swap two bracketed groups";
            }
        }
        8 => {
            let groups = bracket_groups(text);
            if let Some(&(a, b)) = pick(rng, &groups) {
                let s = text[a..b].to_string();
                text.insert_str(b, &format!(",{s}"));
                return "duplicate a bracketed group";
            }
        }
        9 => {
            let attrs = xml_attributes(text);
            if let Some(&r) = pick(rng, &attrs) {
                splice(text, r, "");
                return "drop an XML attribute";
            }
        }
        10 => {
            let elems = xml_elements(text);
            if let Some(&r) = pick(rng, &elems) {
                if rng.below(2) == 0 {
                    splice(text, r, "");
                    return "drop an XML element";
                }
                let s = text[r.0..r.1].to_string();
                text.insert_str(r.1, &s);
                return "duplicate an XML element";
            }
        }
        _ => {}
    }
    // fallback (and choice 11): truncate
    let mut cut = rng.below(text.len() + 1);
    while !text.is_char_boundary(cut) {
        cut -= 1;
    }
    text.truncate(cut);
    "truncate"
}

/// All numbers, arrays and objects of a JSON value, as JSON pointers.
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                pointers(x, format!("{at}/{i}"), out);
            }
        }
        Value::Object(o) => {
            for (k, x) in o {
                pointers(x, format!("{at}/{}", k.replace('~', "~0").replace('/', "~1")), out);
            }
        }
        _ => {}
    }
    out.push(at);
}

/// One value-level edit of a JSON document; `None` when the pointer chosen does not fit.
fn edit_json(v: &mut Value, rng: &mut Lcg) -> Option<&'static str> {
    let mut ptrs = Vec::new();
    pointers(v, String::new(), &mut ptrs);
    let p = pick(rng, &ptrs)?.clone();
    let target = v.pointer_mut(&p)?;
    match (rng.below(5), target) {
        (0, Value::Object(o)) if !o.is_empty() => {
            let k = o.keys().nth(rng.below(o.len()))?.clone();
            o.remove(&k);
            Some("drop a key")
        }
        (1, Value::Array(a)) if a.len() >= 2 => {
            let (i, j) = (rng.below(a.len()), rng.below(a.len()));
            a.swap(i, j);
            Some("swap two array elements")
        }
        (2, Value::Array(a)) if !a.is_empty() => {
            let i = rng.below(a.len());
            if rng.below(2) == 0 {
                a.remove(i);
                Some("remove an array element")
            } else {
                let x = a[i].clone();
                a.insert(i, x);
                Some("duplicate an array element")
            }
        }
        (3, t @ Value::Number(_)) => {
            let x = SPECIAL_VALUES[rng.below(SPECIAL_VALUES.len())];
            *t = match rng.below(3) {
                0 => Value::from(x),
                1 => Value::from(u64::MAX - rng.below(3) as u64),
                _ => Value::from(-(rng.below(1 << 20) as i64)),
            };
            Some("replace a number value")
        }
        (4, t) => {
            *t = match rng.below(5) {
                0 => Value::Null,
                1 => Value::from("x"),
                2 => Value::Array(Vec::new()),
                3 => Value::Object(Default::default()),
                _ => Value::Bool(true),
            };
            Some("change a value's type")
        }
        _ => None,
    }
}

/// Whether `text` is an IGES file ([`crate::io::iges::is_iges`]).
fn is_iges(text: &str) -> bool {
    crate::io::iges::is_iges(text)
}

/// One edit of the data columns of a random Parameter Data record of an IGES file,
/// keeping every record 80 columns wide.
fn edit_iges(text: &str, rng: &mut Lcg) -> (String, &'static str) {
    let lines: Vec<&str> = text.lines().collect();
    let p: Vec<usize> =
        (0..lines.len()).filter(|&k| lines[k].len() == 80 && lines[k].is_ascii() && &lines[k][72..73] == "P").collect();
    let Some(&k) = pick(rng, &p) else {
        let mut t = text.to_string();
        let what = edit_text(&mut t, rng);
        return (t, what);
    };
    let mut data = lines[k][..64].trim_end().to_string();
    let what = edit_text(&mut data, rng);
    let data: String = data.chars().filter(|c| c.is_ascii() && *c != '\n').take(64).collect();
    let mut out = String::with_capacity(text.len());
    for (i, l) in lines.iter().enumerate() {
        if i == k {
            out.push_str(&format!("{data:<64}{}", &l[64..]));
        } else {
            out.push_str(l);
        }
        out.push('\n');
    }
    (out, what)
}

/// `1..=3` random edits of `text`; returns the edited text and the edits' names.
pub fn mutate(text: &str, rng: &mut Lcg) -> (String, Vec<&'static str>) {
    let mut out = text.to_string();
    let mut names = Vec::new();
    for _ in 0..1 + rng.below(3) {
        if is_iges(&out) && rng.below(4) != 0 {
            let (t, what) = edit_iges(&out, rng);
            out = t;
            names.push(what);
            continue;
        }
        if rng.below(2) == 0 {
            if let Ok(mut v) = serde_json::from_str::<Value>(&out) {
                if let Some(what) = edit_json(&mut v, rng) {
                    out = v.to_string();
                    names.push(what);
                    continue;
                }
            }
        }
        names.push(edit_text(&mut out, rng));
    }
    (out, names)
}

/// A mutant that panicked or broke a property.
#[derive(Debug, Clone)]
pub struct Failure {
    /// Name of the file it was made from.
    pub file: String,
    /// Its index among that file's mutants.
    pub mutant: usize,
    /// The edits made.
    pub edits: Vec<&'static str>,
    /// The mutated text.
    pub input: String,
    /// The panic message or the violated property.
    pub problem: String,
}

/// Run `f`, turning a panic into `Err(message)`.
pub fn catch<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic with a non-string payload".into());
        format!("panic: {msg}")
    })
}

/// Make `per_file` mutants of each `(name, text)` ([`mutate`], seeded by `seed`, the
/// file's index and the mutant's) and give each to `check`, which returns the
/// properties it found violated. Every panic and every violation is a [`Failure`].
pub fn run_mutants(
    files: &[(String, String)],
    per_file: usize,
    seed: u64,
    check: impl Fn(&str, &str) -> Vec<String>,
) -> Vec<Failure> {
    let mut failures = Vec::new();
    for (f, (name, text)) in files.iter().enumerate() {
        for m in 0..per_file {
            let mut rng = Lcg::new(seed ^ ((f as u64) << 32) ^ m as u64);
            let (input, edits) = mutate(text, &mut rng);
            let problems = match catch(|| check(name, &input)) {
                Ok(v) => v,
                Err(panic) => vec![panic],
            };
            for problem in problems {
                failures.push(Failure {
                    file: name.clone(),
                    mutant: m,
                    edits: edits.clone(),
                    input: input.clone(),
                    problem,
                });
            }
        }
    }
    failures
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_cover_the_text() {
        let text = "{\"a\": [-1.5e-3, 2], \"b\": \"x_1\"}\n<c d=\"1.D0\"/>";
        let toks = tokens(text);
        let joined: String = toks.iter().map(|t| &text[t.start..t.end]).collect();
        assert_eq!(joined, text);
        let nums: Vec<&str> = toks.iter().filter(|t| t.kind == Kind::Number).map(|t| &text[t.start..t.end]).collect();
        assert_eq!(nums, ["-1.5e-3", "2", "1.D0"]);
    }

    #[test]
    fn edits_change_the_text_and_keep_iges_columns() {
        let json = r#"{"map": {"degree": [1, 1], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]]}}"#;
        let mut rng = Lcg::new(1);
        let mut changed = 0;
        for _ in 0..200 {
            let (m, names) = mutate(json, &mut rng);
            assert!(!names.is_empty());
            changed += usize::from(m != json);
        }
        assert!(changed > 150, "{changed}");
        let iges = format!("{:<72}S{:>7}\n{:<64}{:>8}P{:>7}\n", "start", 1, "128,1,1,1,1,0,0,1,0,0,0,0,1,1;", 1, 1);
        for _ in 0..50 {
            let (t, what) = edit_iges(&iges, &mut rng);
            assert!(t.lines().all(|l| l.len() == 80), "{what}: {t}");
            assert_eq!(&t.lines().nth(1).unwrap()[64..], &iges.lines().nth(1).unwrap()[64..]);
        }
    }

    #[test]
    fn elements_and_attributes_are_found() {
        let xml = r#"<a x="1"><b y="2">t</b><c/></a>"#;
        let e: Vec<&str> = xml_elements(xml).iter().map(|&(a, b)| &xml[a..b]).collect();
        assert_eq!(e, [xml, "<b y=\"2\">t</b>", "<c/>"]);
        let a: Vec<&str> = xml_attributes(xml).iter().map(|&(a, b)| &xml[a..b]).collect();
        assert_eq!(a, [" x=\"1\"", " y=\"2\""]);
    }
}
