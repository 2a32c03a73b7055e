//! The command line's option values and its documentation, through the binary: every numeric
//! option of every subcommand refuses a value out of its range as it is parsed (exit code 2,
//! a message naming the option, the value and the accepted range); every subcommand's
//! `--help` has examples and the exit codes; `streaklight man DIR` writes a page per
//! subcommand that groff reads without a warning and that documents the exit codes.
//!
//! Needs `groff` (`scripts/test` installs it).

mod common;

use std::path::Path;
use std::process::Command;

use common::cli::run_cli_code as run;

/// The subcommands and the arguments each needs besides its options (files that need not
/// exist: values are checked before anything is read).
const COMMANDS: [(&str, &[&str]); 7] = [
    ("fit", &["s.gltf", "p.png", "-o", "o.gltf"]),
    ("segment", &["s.gltf", "p.png", "--out-dir", "d"]),
    ("render", &["s.gltf", "-o", "o.png"]),
    ("restore-lights", &["i.gltf", "-o", "o.gltf"]),
    ("samples", &["d"]),
    ("completions", &["bash"]),
    ("man", &["d"]),
];

/// Bad values of the numeric options, per subcommand, with words of the accepted range.
const BAD_VALUES: [(&str, &str, &str, &str); 41] = [
    ("fit", "--exposure", "-1", "greater than 0 or \"auto\""),
    ("fit", "--exposure", "0", "greater than 0"),
    (
        "fit",
        "--exposure",
        "often",
        "a number greater than 0 or \"auto\"",
    ),
    ("fit", "--gloss", "-5", "greater than 0"),
    ("fit", "--ior", "1", "greater than 1"),
    ("fit", "--nits-scale", "0", "greater than 0"),
    ("fit", "--samples", "0", "whole number from 1"),
    ("fit", "--samples", "-8", "whole number from 1"),
    ("fit", "--seed", "-1", "whole number from 0"),
    ("fit", "--repeats", "0", "whole number from 1"),
    ("fit", "--joint-samples", "0", "whole number from 1"),
    ("fit", "--light-offset", "-0.001", "0 or more"),
    ("fit", "--superpixels", "0", "whole number from 1"),
    ("fit", "--compactness", "0", "greater than 0"),
    ("fit", "--seed-row-step", "0", "whole number from 1"),
    (
        "fit",
        "--seed-threshold",
        "1",
        "up to, but not including, 1",
    ),
    ("fit", "--seed-threshold", "-0.1", "from 0"),
    ("fit", "--blur", "51", "from 0 to 50"),
    ("fit", "--similarity", "1.5", "from -1 to 1"),
    ("fit", "--min-value", "-0.2", "from 0 to 1"),
    ("fit", "--method", "best", "possible values"),
    ("fit", "--water-model", "wavy", "possible values"),
    ("segment", "--exposure", "-0.1", "greater than 0"),
    ("segment", "--superpixels", "-4", "whole number from 1"),
    ("segment", "--compactness", "-1", "greater than 0"),
    ("segment", "--seed-row-step", "1.5", "whole number from 1"),
    ("segment", "--seed-threshold", "2", "not including, 1"),
    ("segment", "--blur", "-1", "from 0 to 50"),
    ("segment", "--similarity", "-2", "from -1 to 1"),
    ("segment", "--min-value", "1.01", "from 0 to 1"),
    ("render", "--width", "0", "whole number from 1"),
    ("render", "--height", "-600", "whole number from 1"),
    ("render", "--spp", "0", "whole number from 1"),
    ("render", "--exposure", "-0.1", "greater than 0"),
    ("render", "--exposure", "auto", "a number greater than 0"),
    ("render", "--seed", "x", "whole number from 0"),
    ("render", "--gloss", "0", "greater than 0"),
    ("render", "--ior", "0.5", "greater than 1"),
    ("render", "--nits-scale", "-683", "greater than 0"),
    ("samples", "--spp", "-1", "whole number from 1"),
    ("completions", "", "tcsh", "possible values"),
];

#[test]
fn values_out_of_range_are_usage_errors_naming_the_option_value_and_range() {
    for (command, flag, value, range) in BAD_VALUES {
        let (_, needed) = COMMANDS.iter().find(|(c, _)| *c == command).unwrap();
        let mut args = vec![command];
        if flag.is_empty() {
            // A positional value: it replaces the needed one.
            args.push(value);
        } else {
            args.extend(needed.iter());
            args.extend([flag, value]);
        }
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(
            stderr.contains(&format!("'{value}'"))
                && stderr.contains(flag)
                && stderr.contains(range),
            "{args:?}: {stderr}"
        );
        assert!(
            !stderr.contains("unexpected argument"),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn values_in_range_get_past_the_parser() {
    // The edges of each range parse: the run then fails on the missing files (exit 1), not
    // on the values.
    let (code, _, stderr) = run(&[
        "fit",
        "missing.gltf",
        "missing.png",
        "-o",
        "o.gltf",
        "--exposure",
        "auto",
        "--light-offset",
        "0",
        "--seed-threshold",
        "0",
        "--blur",
        "50",
        "--similarity",
        "-1",
        "--min-value",
        "1",
        "--seed",
        "18446744073709551615",
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("missing.gltf"), "{stderr}");
}

#[test]
fn every_subcommand_has_examples_ranges_and_exit_codes_in_its_help() {
    for (command, _) in COMMANDS {
        let (code, stdout, stderr) = run(&[command, "--help"]);
        assert_eq!(code, 0, "{command}: {stderr}");
        for words in [
            "Example",
            "Exit codes:",
            "0  success",
            "1  an input was refused",
            "2  the command line is wrong",
            "3  no light found",
        ] {
            assert!(stdout.contains(words), "{command} --help lacks {words:?}");
        }
    }
    // Each numeric option says its range or typical values.
    for (command, flag, _, _) in BAD_VALUES {
        if flag.is_empty() || matches!(flag, "--method" | "--water-model") {
            continue;
        }
        let (_, stdout, _) = run(&[command, "--help"]);
        let line = stdout
            .lines()
            .skip_while(|l| !l.trim_start().starts_with(flag))
            .take(3)
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            [
                "typical",
                " or more",
                "> 0",
                "above 1",
                " to ",
                "water 1.33",
                "683"
            ]
            .iter()
            .any(|w| line.contains(w)),
            "{command} {flag}: no range in {line:?}"
        );
    }
}

/// `page` rendered as plain text by groff, on long lines without hyphenation; asserts groff
/// gave no warning.
fn groff_text(page: &Path) -> String {
    let out = Command::new("groff")
        .args(["-man", "-Tascii", "-ww", "-rLL=400n", "-rHY=0"])
        .arg(page)
        .output()
        .expect("groff runs (scripts/test installs groff-base)");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && stderr.trim().is_empty(),
        "{}: {stderr}",
        page.display()
    );
    // Drop the overstriking of bold and underlined text.
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let mut plain = String::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        if chars.peek() == Some(&'\u{8}') {
            chars.next();
            continue;
        }
        plain.push(c);
    }
    plain
}

#[test]
fn man_writes_a_page_per_subcommand_with_the_exit_codes() {
    let dir = common::temp_dir("cli-man");
    let pages = dir.join("man1");
    let (code, _, stderr) = run(&["man", pages.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    let main = groff_text(&pages.join("streaklight.1"));
    for (command, _) in COMMANDS {
        assert!(
            main.contains(&format!("streaklight-{command}(1)")),
            "streaklight.1 does not name {command}: {main}"
        );
        let text = groff_text(&pages.join(format!("streaklight-{command}.1")));
        for words in [
            "NAME",
            "SYNOPSIS",
            &format!("streaklight {command}"),
            "Exit codes:",
            "3  no light found",
        ] {
            assert!(
                text.contains(words),
                "streaklight-{command}.1 lacks {words:?}"
            );
        }
    }
    for words in [
        "Exit codes:",
        "0  success",
        "1  an input was refused",
        "2  the command line is wrong",
        "3  no light found",
    ] {
        assert!(main.contains(words), "streaklight.1 lacks {words:?}");
    }
    let fit = groff_text(&pages.join("streaklight-fit.1"));
    assert!(fit.contains("--exposure <E|auto>") && fit.contains("K = 12.5"));
    let mut names = common::dirs::listing(&pages);
    names.sort();
    assert_eq!(names.len(), COMMANDS.len() + 1, "{names:?}");
    // A folder that cannot be made: an error naming it, exit 1.
    let file = dir.join("a-file");
    std::fs::write(&file, "").unwrap();
    let (code, _, stderr) = run(&["man", file.join("man1").to_str().unwrap()]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("a-file"), "{stderr}");
}
