//! One name per concept: walks every subcommand of the parser (what `--help` prints) and
//! checks that an option spelled the same way has the same type, default and kind
//! everywhere, that the shared concepts use their one name, and that old spellings are
//! hidden aliases only.

use std::collections::BTreeMap;

use clap::{Arg, Command, CommandFactory};
use toonkit_cli::Cli;

/// Names that mean different things in different commands (homonyms, not one concept):
/// `--render PATH` writes a picture (segment, animate) while `stopmo run --render` turns the
/// pictures of its folder on; `--thickness` is a tube radius (smear lines) or a wall in mm
/// (stopmo); `--color` picks a colouring (render) or gives RGB (smear lines).
const HOMONYMS: [&str; 3] = ["render", "thickness", "color"];

/// Shared options whose default differs on purpose in one command: `stopmo segment` writes
/// its parts as morph targets by default (its outputs are read back as one mesh per part,
/// which `stopmo library` expects), every other writer defaults to a flipbook; each
/// command that writes a folder of its own names its own default folder.
const OWN_DEFAULTS: [(&str, &str); 2] = [
    ("toonkit stopmo segment", "layout"),
    ("toonkit studio", "out"),
];

/// Each shared concept, its one name, and spellings that must not be visible options.
const CONCEPTS: [(&str, &[&str]); 6] = [
    ("layout", &["as", "format-layout"]),
    ("fps", &["rate", "frame-rate", "framerate"]),
    ("clip", &["animation", "take", "action"]),
    ("seed", &["random-seed", "rng-seed"]),
    ("frame", &["frame-index", "at-frame"]),
    ("mesh", &["object", "meshes"]),
];

/// Every (command path, argument) of the tool, subcommands included.
fn all_args() -> Vec<(String, Arg)> {
    fn walk(path: &str, cmd: &Command, out: &mut Vec<(String, Arg)>) {
        for a in cmd.get_arguments() {
            out.push((path.to_string(), a.clone()));
        }
        for sub in cmd.get_subcommands() {
            walk(&format!("{path} {}", sub.get_name()), sub, out);
        }
    }
    let mut cmd = Cli::command();
    cmd.build();
    let mut out = Vec::new();
    walk("toonkit", &cmd, &mut out);
    out
}

/// What must agree between two options of the same name: value type, defaults, action and
/// number of values.
fn signature(a: &Arg) -> String {
    format!(
        "type {:?}, default {:?}, action {:?}, values {:?}",
        a.get_value_parser().type_id(),
        a.get_default_values(),
        a.get_action(),
        a.get_num_args()
    )
}

#[test]
fn options_with_one_name_have_one_type_and_default() {
    let mut seen: BTreeMap<String, (String, String)> = BTreeMap::new();
    let mut checked = 0;
    for (path, arg) in all_args() {
        let Some(long) = arg.get_long() else { continue };
        if HOMONYMS.contains(&long) || long == "help" || long == "version" {
            continue;
        }
        if OWN_DEFAULTS.contains(&(path.as_str(), long)) {
            assert_ne!(
                arg.get_default_values(),
                [""],
                "--{long} of `{path}` has no default"
            );
            continue;
        }
        let sig = signature(&arg);
        match seen.get(long) {
            Some((first, want)) => {
                assert_eq!(
                    &sig, want,
                    "--{long} differs between `{first}` and `{path}`"
                );
                checked += 1;
            }
            None => {
                seen.insert(long.to_string(), (path, sig));
            }
        }
    }
    // The shared options are really shared (clip/fps/mesh/rest in every reader, layout in
    // convert, elongate and segment, seeds in lines and stopmo).
    assert!(checked > 50, "only {checked} repeated options found");
}

#[test]
fn shared_concepts_use_one_name_and_old_spellings_are_hidden() {
    let args = all_args();
    for (name, others) in CONCEPTS {
        assert!(
            args.iter().any(|(_, a)| a.get_long() == Some(name)),
            "no command has --{name}"
        );
        for (path, a) in &args {
            for other in others.iter() {
                assert_ne!(
                    a.get_long(),
                    Some(*other),
                    "`{path}` spells --{name} as --{other}"
                );
                if let Some(visible) = a.get_visible_aliases() {
                    assert!(!visible.contains(other), "`{path}`: --{other} is shown");
                }
            }
        }
    }
    // `--as` still works, hidden, wherever `--layout` is.
    let layouts: Vec<_> = args
        .iter()
        .filter(|(_, a)| a.get_long() == Some("layout"))
        .collect();
    assert!(
        layouts.len() >= 3,
        "convert, smear elongate, stopmo segment"
    );
    for (path, a) in layouts {
        let hidden = a.get_all_aliases().unwrap_or_default();
        assert!(hidden.contains(&"as"), "`{path}`: --as is not an alias");
    }
}

#[test]
fn as_is_an_alias_of_layout() {
    let convert = |extra: [&str; 2]| {
        let argv = ["toonkit", "convert", "a.glb", "b.obj"]
            .into_iter()
            .chain(extra);
        let matches = Cli::command().try_get_matches_from(argv);
        let matches = matches.expect("convert parses");
        matches
            .subcommand_matches("convert")
            .expect("convert")
            .clone()
    };
    let m = convert(["--as", "sequence"]);
    assert_eq!(
        m.get_one::<tkio::Layout>("layout"),
        Some(&tkio::Layout::Sequence)
    );
    let m = convert(["--frame", "3"]);
    assert_eq!(m.get_one::<usize>("frame"), Some(&3));
}
