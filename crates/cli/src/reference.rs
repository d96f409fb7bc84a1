//! The command-line reference (`docs/cli.md`) written from the clap definitions: the
//! hidden `winslow reference` walks the command tree (every visible subcommand, depth
//! first) and prints, per command, its description, usage, arguments and options with
//! their help, possible values and defaults, and its example (`after_help`) as a shell
//! block. `crates/cli/tests/reference.rs` fails when the committed file differs;
//! regenerate it with `cargo run --bin winslow -- reference > docs/cli.md` (or
//! `WINSLOW_BLESS=1 cargo test -p winslow-cli --test reference`).

use std::fmt::Write;

use clap::{Arg, Command};

/// The Markdown reference of `cmd` (the root command) and all its visible subcommands.
pub(crate) fn markdown(mut cmd: Command) -> String {
    // building propagates the bin names ("winslow solve") that the usage lines show
    cmd.build();
    let mut out = String::new();
    let name = cmd.get_name().to_string();
    let _ = writeln!(out, "# Command-line reference\n");
    let _ = writeln!(
        out,
        "<!-- Generated from the clap definitions by `winslow reference`; do not edit by hand.\n\
         Regenerate: cargo run --bin winslow -- reference > docs/cli.md\n\
         (or WINSLOW_BLESS=1 cargo test -p winslow-cli --test reference) -->\n"
    );
    if let Some(about) = cmd.get_about() {
        let _ = writeln!(out, "{about}\n");
    }
    let _ = writeln!(out, "| command | what it does |\n|---|---|");
    for sub in visible_subcommands(&cmd) {
        let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
        let _ = writeln!(out, "| [`{name} {}`](#{name}-{}) | {} |", sub.get_name(), sub.get_name(), cell(&about));
    }
    out.push('\n');
    let _ = writeln!(out, "Every command also takes `-h` (summary) and `--help` (the text below).\n");
    for sub in visible_subcommands(&cmd) {
        command_section(&mut out, sub, &format!("{name} {}", sub.get_name()), 2);
    }
    out
}

/// The subcommands a user sees (`help` and hidden ones left out), in definition order.
fn visible_subcommands(cmd: &Command) -> impl Iterator<Item = &Command> {
    cmd.get_subcommands().filter(|s| !s.is_hide_set() && s.get_name() != "help")
}

/// One command's section at heading `level`, then its own subcommands one level deeper.
fn command_section(out: &mut String, cmd: &Command, path: &str, level: usize) {
    let hashes = "#".repeat(level.min(6));
    let _ = writeln!(out, "{hashes} {path}\n");
    if let Some(about) = cmd.get_long_about().or(cmd.get_about()) {
        let _ = writeln!(out, "{about}\n");
    }
    let usage = cmd.clone().render_usage().to_string();
    let usage = usage.trim().trim_start_matches("Usage:").trim();
    let _ = writeln!(out, "```text\n{usage}\n```\n");

    let (positionals, options): (Vec<&Arg>, Vec<&Arg>) =
        cmd.get_arguments().filter(|a| !a.is_hide_set()).partition(|a| a.is_positional());
    if !positionals.is_empty() {
        let _ = writeln!(out, "Arguments:\n");
        for arg in positionals {
            argument(out, arg);
        }
        out.push('\n');
    }
    if !options.is_empty() {
        let _ = writeln!(out, "Options:\n");
        for arg in options {
            argument(out, arg);
        }
        out.push('\n');
    }
    if let Some(after) = cmd.get_after_long_help().or(cmd.get_after_help()) {
        example(out, &after.to_string());
    }
    for sub in visible_subcommands(cmd) {
        command_section(out, sub, &format!("{path} {}", sub.get_name()), level + 1);
    }
}

/// One list item: the argument's spelling and default, its help and possible values.
fn argument(out: &mut String, arg: &Arg) {
    let _ = write!(out, "- `{}`", spelling(arg));
    let defaults: Vec<String> = arg.get_default_values().iter().map(|v| v.to_string_lossy().into_owned()).collect();
    if !defaults.is_empty() && arg.get_action().takes_values() {
        let _ = write!(out, " (default `{}`)", defaults.join(","));
    }
    let help = arg.get_long_help().or(arg.get_help()).map(|h| h.to_string()).unwrap_or_default();
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    if !help.is_empty() {
        let stop = if help.ends_with('.') { "" } else { "." };
        let _ = write!(out, ": {help}{stop}");
    }
    let values: Vec<String> = arg
        .get_possible_values()
        .iter()
        .filter(|v| !v.is_hide_set())
        .map(|v| match v.get_help() {
            Some(h) => format!("`{}` ({})", v.get_name(), h),
            None => format!("`{}`", v.get_name()),
        })
        .collect();
    if !values.is_empty() && arg.get_action().takes_values() {
        let _ = write!(out, " Values: {}.", values.join(", "));
    }
    out.push('\n');
}

/// `-o, --output <OUTPUT>`, `--json`, `<SLICES>...`, `[BOUNDARY]`.
fn spelling(arg: &Arg) -> String {
    let names: Vec<String> = arg
        .get_value_names()
        .map(|v| v.iter().map(|n| n.to_string()).collect())
        .unwrap_or_else(|| vec![arg.get_id().as_str().to_uppercase()]);
    let many = arg.get_num_args().is_some_and(|n| n.max_values() > names.len());
    if arg.is_positional() {
        let name = &names[0];
        let core = if arg.is_required_set() { format!("<{name}>") } else { format!("[{name}]") };
        return if many { format!("{core}...") } else { core };
    }
    let mut s = String::new();
    if let Some(short) = arg.get_short() {
        let _ = write!(s, "-{short}, ");
    }
    if let Some(long) = arg.get_long() {
        let _ = write!(s, "--{long}");
    }
    if arg.get_action().takes_values() {
        for n in &names {
            let _ = write!(s, " <{n}>");
        }
        if many {
            s.push_str("...");
        }
    }
    s
}

/// The `after_help` text: a first line ("Example:") and shell lines indented below it
/// become a paragraph and a `sh` block; anything else is kept as text.
fn example(out: &mut String, text: &str) {
    let mut lines = text.lines();
    let head = lines.next().unwrap_or_default().trim();
    let body: Vec<&str> = lines.map(str::trim).filter(|l| !l.is_empty()).collect();
    if head.ends_with(':') && !body.is_empty() {
        let _ = writeln!(out, "{head}\n\n```sh\n{}\n```\n", body.join("\n"));
    } else {
        let _ = writeln!(out, "```text\n{}\n```\n", text.trim());
    }
}

/// Text fit for a table cell (no line breaks, no column separators).
fn cell(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ").replace('|', "\\|")
}
