//! The corpus of bad inputs (`tests/corpus/`, laid out as its README.md says): every case
//! runs the release binary once, in a temporary copy of its folder, with stdin closed, a
//! timeout and a 2 GiB address-space limit, and must fail the way its `case.toml` says:
//! the expected exit code (never a signal, a panic or an abort), the expected words on
//! stderr, no "panicked", no half-written output folder, inputs it must keep intact.
//! Every failing case is reported at once, one line each, before the test fails; a corpus
//! smaller than [`MIN_CASES`] or a harness that cannot tell a pass from a failure fails
//! too, so the test never passes vacuously.

use serde::Deserialize;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Cases committed: the corpus may grow, never shrink unnoticed.
const MIN_CASES: usize = 137;

/// The address-space limit of every run, in KiB (`ulimit -v`): 2 GiB.
const MEMORY_KIB: u64 = 2 * 1024 * 1024;

/// Lines of stderr quoted in a failure report.
const QUOTED_LINES: usize = 3;

/// One case, as its `case.toml` describes it (see tests/corpus/README.md).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    /// The command line after the binary: `{case}`, `{out}` and `{repo}` are replaced.
    args: Vec<String>,
    /// The exit code expected, or the codes accepted.
    exit: Exit,
    /// Substrings stderr must contain.
    #[serde(default)]
    stderr: Vec<String>,
    /// Substrings stderr must not contain.
    #[serde(default)]
    stderr_not: Vec<String>,
    /// Substrings stdout must contain.
    #[serde(default)]
    stdout: Vec<String>,
    /// Substrings stdout must not contain.
    #[serde(default)]
    stdout_not: Vec<String>,
    /// The longest run of digits stderr may hold.
    max_digits: Option<usize>,
    /// Files of the case folder that must be left byte for byte as they were.
    #[serde(default)]
    keep: Vec<String>,
    /// Steps run before the command, in order.
    #[serde(default)]
    prepare: Vec<Step>,
    /// The audit item the case comes from.
    defect: Option<String>,
    /// Seconds before the run is killed and reported.
    #[serde(default = "default_timeout")]
    timeout_s: f64,
    /// Send SIGTERM (an interrupt, as Ctrl-C) after this many seconds.
    interrupt_after_s: Option<f64>,
}

fn default_timeout() -> f64 {
    20.0
}

/// `exit = 1` or `exit = [1, 2]`.
#[derive(Deserialize)]
#[serde(untagged)]
enum Exit {
    One(i32),
    Any(Vec<i32>),
}

impl Exit {
    fn accepts(&self, code: i32) -> bool {
        match self {
            Exit::One(c) => *c == code,
            Exit::Any(cs) => cs.contains(&code),
        }
    }

    fn describe(&self) -> String {
        match self {
            Exit::One(c) => c.to_string(),
            Exit::Any(cs) => format!("one of {cs:?}"),
        }
    }
}

/// A step of `prepare`: `{ do = "shards", count = 2, photons = 10000 }` and so on.
#[derive(Deserialize)]
#[serde(tag = "do", rename_all = "snake_case", deny_unknown_fields)]
enum Step {
    /// Trace shards `0/count` .. `count-1/count` of the case's scene into `s0`, `s1`, ...
    Shards { count: u32, photons: u64 },
    /// Make `path` a symbolic link to `to`, replacing any file there.
    Symlink { path: String, to: String },
    /// Make `path` a FIFO (`mkfifo`), replacing any file there.
    Fifo { path: String },
    /// Replace the JSON value that follows the first `after` in `file` by `value`.
    Edit {
        file: String,
        after: String,
        value: String,
    },
}

/// What one run did.
struct Run {
    status: Option<ExitStatus>,
    stdout: String,
    stderr: String,
}

/// The folders of one case's run: all inside one temporary folder, removed on drop.
struct Sandbox {
    _dir: tempfile::TempDir,
    root: PathBuf,
    case: PathBuf,
    out: PathBuf,
    tmp: PathBuf,
}

impl Sandbox {
    /// A fresh temporary folder holding a copy of `source` (the case folder) as `case/`.
    fn new(source: &Path) -> std::io::Result<Sandbox> {
        let dir = tempfile::Builder::new()
            .prefix("blutrace-bad-input-")
            .tempdir()?;
        let root = dir.path().to_path_buf();
        let case = root.join("case");
        copy_folder(source, &case)?;
        let tmp = root.join("tmp");
        std::fs::create_dir(&tmp)?;
        std::fs::create_dir(root.join("logs"))?;
        Ok(Sandbox {
            out: root.join("run-out"),
            _dir: dir,
            root,
            case,
            tmp,
        })
    }

    /// `arg` with `{case}`, `{out}` and `{repo}` replaced.
    fn expand(&self, arg: &str) -> String {
        arg.replace("{case}", &self.case.to_string_lossy())
            .replace("{out}", &self.out.to_string_lossy())
            .replace("{repo}", env!("CARGO_MANIFEST_DIR"))
    }

    /// Run the binary with `args` (expanded) in this sandbox.
    fn run(&self, args: &[String], timeout: f64, interrupt: Option<f64>) -> Result<Run, String> {
        let args: Vec<String> = args.iter().map(|a| self.expand(a)).collect();
        run_limited(self, &args, timeout, interrupt).map_err(|e| format!("cannot run: {e}"))
    }
}

/// Copy the regular files and folders below `from` to `to`.
fn copy_folder(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let kind = entry.file_type()?;
        let target = to.join(entry.file_name());
        if kind.is_dir() {
            copy_folder(&entry.path(), &target)?;
        } else if kind.is_file() {
            std::fs::copy(entry.path(), target)?;
        } else {
            let what = format!("{}: not a file or folder", entry.path().display());
            return Err(std::io::Error::other(what));
        }
    }
    Ok(())
}

/// Run the binary through `sh` (to set `ulimit -v`), stdin closed, stdout and stderr to
/// files, in the sandbox's root with TMPDIR inside it; SIGTERM after `interrupt` s,
/// killed after `timeout` s.
fn run_limited(
    sb: &Sandbox,
    args: &[String],
    timeout: f64,
    interrupt: Option<f64>,
) -> std::io::Result<Run> {
    let logs = sb.root.join("logs");
    let (out_file, err_file) = (logs.join("stdout"), logs.join("stderr"));
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_KIB}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_blutrace"))
        .args(args)
        .current_dir(&sb.root)
        .env("TMPDIR", &sb.tmp)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_file)?)
        .stderr(std::fs::File::create(&err_file)?)
        .spawn()?;
    let start = Instant::now();
    let mut interrupted = false;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        let elapsed = start.elapsed().as_secs_f64();
        if interrupt.is_some_and(|t| elapsed >= t) && !interrupted {
            interrupted = true;
            Command::new("kill")
                .args(["-TERM", &child.id().to_string()])
                .status()?;
        }
        if elapsed >= timeout {
            child.kill()?;
            child.wait()?;
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let read = |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default()).into();
    Ok(Run {
        status,
        stdout: read(&out_file),
        stderr: read(&err_file),
    })
}

/// Run the case's `prepare` steps in the sandbox.
fn prepare(sb: &Sandbox, steps: &[Step]) -> Result<(), String> {
    for step in steps {
        match step {
            Step::Shards { count, photons } => trace_shards(sb, *count, *photons)?,
            Step::Symlink { path, to } => {
                let at = fresh_path(sb, path)?;
                std::os::unix::fs::symlink(to, &at).map_err(|e| format!("symlink {path}: {e}"))?
            }
            Step::Fifo { path } => {
                let at = fresh_path(sb, path)?;
                let made = Command::new("mkfifo").arg(&at).status();
                if !made.is_ok_and(|s| s.success()) {
                    return Err(format!("mkfifo {path} failed"));
                }
            }
            Step::Edit { file, after, value } => edit_json(&sb.case.join(file), after, value)
                .map_err(|e| format!("edit {file}: {e}"))?,
        }
    }
    Ok(())
}

/// `path` in the case folder, with whatever was there removed.
fn fresh_path(sb: &Sandbox, path: &str) -> Result<PathBuf, String> {
    let at = sb.case.join(path);
    if at.symlink_metadata().is_ok() {
        std::fs::remove_file(&at).map_err(|e| format!("remove {path}: {e}"))?;
    }
    Ok(at)
}

/// Trace the shards of the case's scene into `s0`, `s1`, ... of the case folder.
fn trace_shards(sb: &Sandbox, count: u32, photons: u64) -> Result<(), String> {
    for k in 0..count {
        let args: Vec<String> = [
            "trace",
            "{case}",
            "--photons",
            &photons.to_string(),
            "--shard",
            &format!("{k}/{count}"),
            "--quiet",
            "--out",
            &format!("{{case}}/s{k}"),
        ]
        .map(String::from)
        .to_vec();
        let run = sb.run(&args, 60.0, None)?;
        if !run.status.is_some_and(|s| s.success()) {
            return Err(format!(
                "shard {k}/{count} failed: {}",
                first_lines(&run.stderr)
            ));
        }
    }
    Ok(())
}

/// Replace the JSON value right after the first `after` in `file` by `value`, as text:
/// a shard's tallies are exact 128-bit integers that a round trip through
/// `serde_json::Value` would turn into floats. serde_json checks the result is JSON.
fn edit_json(file: &Path, after: &str, value: &str) -> Result<(), String> {
    let text = std::fs::read_to_string(file).map_err(|e| e.to_string())?;
    let at = text.find(after).ok_or(format!("no {after:?}"))? + after.len();
    let end = at + json_value_len(&text[at..]).ok_or(format!("no value after {after:?}"))?;
    let edited = format!("{}{value}{}", &text[..at], &text[end..]);
    serde_json::from_str::<serde_json::Value>(&edited)
        .map_err(|e| format!("the edit is not JSON: {e}"))?;
    if edited == text {
        return Err("the edit changes nothing".into());
    }
    std::fs::write(file, edited).map_err(|e| e.to_string())
}

/// The length in bytes of the JSON value at the start of `s` (an array, object, string
/// or scalar), or `None` when there is none.
fn json_value_len(s: &str) -> Option<usize> {
    let (mut depth, mut in_string, mut escaped) = (0usize, false, false);
    for (i, c) in s.char_indices() {
        if in_string {
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') if depth == 0 => return Some(i + 1),
                (false, '"') => in_string = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => in_string = true,
            '[' | '{' => depth += 1,
            ']' | '}' if depth == 0 => return (i > 0).then_some(i),
            ']' | '}' if depth == 1 => return Some(i + 1),
            ']' | '}' => depth -= 1,
            ',' if depth == 0 => return (i > 0).then_some(i),
            _ => {}
        }
    }
    (depth == 0 && !s.is_empty()).then_some(s.len())
}

/// The first lines of `text`, on one line.
fn first_lines(text: &str) -> String {
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .take(QUOTED_LINES)
        .collect();
    if lines.is_empty() {
        "(empty)".into()
    } else {
        lines.join(" / ")
    }
}

/// How a run ended and the first lines of its stderr, for `BAD_INPUTS_VERBOSE=1`.
fn describe(run: &Run) -> String {
    let ended = match run.status {
        None => "killed at its timeout".to_string(),
        Some(s) => match (s.code(), s.signal()) {
            (Some(code), _) => format!("exit {code}"),
            (_, sig) => format!("signal {sig:?}"),
        },
    };
    format!("{ended}; stderr: {}", first_lines(&run.stderr))
}

/// The longest run of ASCII digits in `text`.
fn longest_digit_run(text: &str) -> usize {
    text.split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0)
}

/// What is wrong with the exit status, or nothing.
fn status_problems(case: &Case, run: &Run) -> Vec<String> {
    let Some(status) = run.status else {
        return vec![format!(
            "did not finish within {} s (killed)",
            case.timeout_s
        )];
    };
    match (status.code(), status.signal()) {
        (_, Some(sig)) => vec![format!("ended by signal {sig}")],
        (Some(101), _) => vec!["panicked (exit 101)".into()],
        (Some(134), _) => vec!["aborted (exit 134)".into()],
        (Some(code), _) if !case.exit.accepts(code) => {
            vec![format!("exit {code}, expected {}", case.exit.describe())]
        }
        _ => vec![],
    }
}

/// The expected and forbidden substrings of one stream.
fn text_problems(name: &str, text: &str, must: &[String], must_not: &[String]) -> Vec<String> {
    let lacks = must
        .iter()
        .filter(|w| !text.contains(w.as_str()))
        .map(|w| format!("{name} lacks {w:?}"));
    let has = must_not
        .iter()
        .filter(|w| text.contains(w.as_str()))
        .map(|w| format!("{name} holds {w:?}"));
    lacks.chain(has).collect()
}

/// An output folder left behind by a run that failed (a run interrupted on purpose,
/// exit 130, writes a complete set by design).
fn output_problems(case: &Case, sb: &Sandbox, run: &Run) -> Vec<String> {
    let names_out = case.args.iter().any(|a| a.contains("{out}"));
    let failed = run
        .status
        .and_then(|s| s.code())
        .is_none_or(|c| c != 0 && c != 130);
    if !names_out || !failed {
        return vec![];
    }
    match std::fs::read_dir(&sb.out) {
        Err(_) => vec![],
        Ok(entries) => {
            let left: Vec<String> = entries
                .filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect();
            if left.is_empty() {
                vec![]
            } else {
                vec![format!("failed but left {left:?} in its output folder")]
            }
        }
    }
}

/// Files that had to stay as they were.
fn kept_problems(sb: &Sandbox, before: &[(String, Option<Vec<u8>>)]) -> Vec<String> {
    before
        .iter()
        .filter(|(f, bytes)| std::fs::read(sb.case.join(f)).ok() != *bytes)
        .map(|(f, _)| format!("{f} was changed or deleted"))
        .collect()
}

/// Run one case from its folder: the list of what went wrong (empty when it passed).
fn check_case(folder: &Path, case: &Case) -> Vec<String> {
    let sb = match Sandbox::new(folder) {
        Ok(sb) => sb,
        Err(e) => return vec![format!("cannot copy the case: {e}")],
    };
    if let Err(e) = prepare(&sb, &case.prepare) {
        return vec![format!("prepare: {e}")];
    }
    let before: Vec<(String, Option<Vec<u8>>)> = case
        .keep
        .iter()
        .map(|f| (f.clone(), std::fs::read(sb.case.join(f)).ok()))
        .collect();
    let run = match sb.run(&case.args, case.timeout_s, case.interrupt_after_s) {
        Ok(run) => run,
        Err(e) => return vec![e],
    };
    if std::env::var_os("BAD_INPUTS_VERBOSE").is_some() {
        eprintln!("{}: {}", folder.display(), describe(&run));
    }
    let mut problems = judge(case, &run);
    problems.extend(output_problems(case, &sb, &run));
    problems.extend(kept_problems(&sb, &before));
    if !problems.is_empty() {
        problems.push(format!("stderr: {}", first_lines(&run.stderr)));
    }
    problems
}

/// What is wrong with a run's exit status, stderr and stdout.
fn judge(case: &Case, run: &Run) -> Vec<String> {
    let mut problems = status_problems(case, run);
    let mut stderr_not = case.stderr_not.clone();
    stderr_not.push("panicked".into());
    problems.extend(text_problems(
        "stderr",
        &run.stderr,
        &case.stderr,
        &stderr_not,
    ));
    problems.extend(text_problems(
        "stdout",
        &run.stdout,
        &case.stdout,
        &case.stdout_not,
    ));
    let longest = longest_digit_run(&run.stderr);
    if case.max_digits.is_some_and(|max| longest > max) {
        problems.push(format!("stderr holds a {longest}-digit number"));
    }
    problems
}

/// Read a `case.toml`.
fn read_case(file: &Path) -> Result<Case, String> {
    let text = std::fs::read_to_string(file).map_err(|e| e.to_string())?;
    let case: Case = toml::from_str(&text).map_err(|e| e.to_string())?;
    let expects = case.stderr.len() + case.stdout.len() + case.stdout_not.len();
    if expects == 0 {
        return Err("expects nothing of stderr or stdout".into());
    }
    Ok(case)
}

/// The case folders, sorted.
fn case_folders() -> Vec<PathBuf> {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&corpus)
        .unwrap_or_else(|e| panic!("{}: {e}", corpus.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    folders
}

/// The harness tells a pass from a failure: a case whose expectations are wrong fails
/// with a line for each, and one whose expectations hold passes.
fn assert_the_harness_discriminates() {
    let dir = tempfile::tempdir().unwrap();
    let case = |toml: &str| -> Case { toml::from_str(toml).unwrap() };
    let wrong = case("args = [\"check\", \"{case}\"]\nexit = 0\nstderr = [\"no such words\"]");
    let problems = check_case(dir.path(), &wrong);
    assert!(
        problems.len() >= 2,
        "wrong expectations passed: {problems:?}"
    );
    let right = case("args = [\"check\", \"{case}\"]\nexit = 1\nstderr = [\"scene.toml\"]");
    let problems = check_case(dir.path(), &right);
    assert!(
        problems.is_empty(),
        "right expectations failed: {problems:?}"
    );
}

#[test]
fn every_bad_input_in_the_corpus_is_refused_cleanly() {
    assert_the_harness_discriminates();
    let folders = case_folders();
    let start = Instant::now();
    let mut failures = Vec::new();
    for folder in &folders {
        let name = folder.file_name().unwrap().to_string_lossy().into_owned();
        let (label, problems) = match read_case(&folder.join("case.toml")) {
            Ok(case) => match &case.defect {
                Some(d) => (format!("{name} ({d})"), check_case(folder, &case)),
                None => (name, check_case(folder, &case)),
            },
            Err(e) => (name, vec![format!("case.toml: {e}")]),
        };
        if !problems.is_empty() {
            failures.push(format!("{label}: {}", problems.join("; ")));
        }
    }
    eprintln!(
        "{} cases in {:.1} s, {} failing",
        folders.len(),
        start.elapsed().as_secs_f64(),
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        folders.len(),
        failures.join("\n")
    );
    assert!(
        folders.len() >= MIN_CASES,
        "the corpus has {} cases, fewer than the {MIN_CASES} committed",
        folders.len()
    );
}
