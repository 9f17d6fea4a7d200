//! `morphfx job openjd -o DIR -- morph ARGS...` (or `-- warp ...`): an Open
//! Job Description job bundle for that exact command line, as AWS Deadline
//! Cloud takes one: `template.yaml` (the project's template), the command's
//! values in `parameter_values.yaml` (Deadline Cloud's form, for `deadline
//! bundle submit DIR`) and in `openjd_parameters.json` (for `openjd run
//! DIR/template.yaml -p file://DIR/openjd_parameters.json`). The values are
//! not the template's defaults: the spec allows a PATH default only inside
//! the template's own folder.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::host::HostError;
use crate::io::write_text;
use crate::sequence::{openjd_frames, parse_frames};

const MORPH_TEMPLATE: &str = include_str!("../../../farm/openjd/morph.template.yaml");
const WARP_TEMPLATE: &str = include_str!("../../../farm/openjd/warp.template.yaml");

/// What `morphfx job openjd` was asked for.
pub struct Job<'a> {
    pub dir: &'a Path,
    pub chunk_size: u32,
    pub chunk_target_runtime: u32,
    pub morphfx: &'a str,
    /// The bundle `--bundle` named, if any: its folder becomes the job's
    /// PluginPath (`morphfx --plugin-path` on the workers).
    pub plugin_path: Option<&'a Path>,
    /// `morph ...` or `warp ...`.
    pub command: &'a [String],
}

/// Each job parameter's name and value (a string or an integer).
type Values = Vec<(&'static str, Value)>;

/// Writes the job bundle for `job.command` into `job.dir`, once the
/// command fits the template and `check` (what a worker would check first)
/// passes: a job that cannot run leaves nothing written.
pub fn write_bundle(
    job: &Job,
    check: impl FnOnce() -> Result<(), HostError>,
) -> Result<(), HostError> {
    let (template, values) = job_values(job)?;
    check()?;
    let mut deadline = String::from("parameterValues:\n");
    for (name, value) in &values {
        // A JSON scalar is a YAML one (strings double-quoted).
        deadline += &format!("  - name: {name}\n    value: {value}\n");
    }
    let openjd: serde_json::Map<String, Value> = values
        .iter()
        .map(|(name, value)| (name.to_string(), value.clone()))
        .collect();
    let openjd = serde_json::to_string_pretty(&openjd).unwrap_or_default() + "\n";
    std::fs::create_dir_all(job.dir)
        .map_err(|e| HostError::bad(format!("{}: {e}", job.dir.display())))?;
    write_text(&job.dir.join("template.yaml"), template)?;
    write_text(&job.dir.join("parameter_values.yaml"), &deadline)?;
    write_text(&job.dir.join(OPENJD_PARAMETERS), &openjd)?;
    let dir = job.dir.display();
    println!("job bundle: {dir}");
    println!("  run it here:  openjd run {dir}/template.yaml -p file://{dir}/{OPENJD_PARAMETERS}");
    println!("  submit it:    deadline bundle submit {dir}");
    Ok(())
}

/// The job's values as `openjd run -p file://...` reads them (a map; Deadline
/// Cloud's `parameter_values.yaml` is a list of names and values).
pub const OPENJD_PARAMETERS: &str = "openjd_parameters.json";

/// The template for the command's node, and every parameter's value.
fn job_values(job: &Job) -> Result<(&'static str, Values), HostError> {
    let (node, args) = job
        .command
        .split_first()
        .ok_or_else(|| HostError::bad("morphfx job openjd: no command after --"))?;
    let (template, inputs): (&str, &[(&str, &'static str)]) = match node.as_str() {
        "morph" => (MORPH_TEMPLATE, &[("--a", "A"), ("--b", "B")]),
        "warp" => (WARP_TEMPLATE, &[("--input", "Input")]),
        other => {
            return Err(HostError::bad(format!(
                "morphfx job openjd: the command is `{other}`; a farm job runs morph or warp"
            )))
        }
    };
    if job.chunk_size == 0 {
        return Err(HostError::bad(
            "morphfx job openjd: --chunk-size must be at least 1",
        ));
    }
    let options = Options::parse(args)?;
    let plugin_path = match job.plugin_path {
        Some(p) => absolute(&bundle_folder(p))?,
        None => String::new(),
    };
    let mut values = vec![
        ("Morphfx", Value::from(command_path(job.morphfx)?)),
        ("PluginPath", Value::from(plugin_path)),
        (
            "Scene",
            Value::from(absolute(Path::new(options.value("--scene")?))?),
        ),
    ];
    for (flag, name) in inputs {
        values.push((
            name,
            Value::from(absolute(Path::new(options.value(flag)?))?),
        ));
    }
    let frames = options.value("--frames")?;
    parse_frames(frames)?;
    let frames = openjd_frames(frames);
    values.extend([
        (
            "Output",
            Value::from(absolute(Path::new(options.value("-o")?))?),
        ),
        ("Frames", Value::from(frames)),
        ("ChunkSize", Value::from(job.chunk_size)),
        ("ChunkTargetRuntime", Value::from(job.chunk_target_runtime)),
        ("ExtraArgs", Value::from(options.extra(inputs)?)),
    ]);
    Ok((template, values))
}

/// The command's options: the values the template's parameters carry, and
/// the rest, which become its extra arguments.
struct Options {
    pairs: Vec<(String, String)>,
    rest: Vec<String>,
}

/// Options the template carries as parameters, each with a value.
const CARRIED: [&str; 6] = ["--scene", "--a", "--b", "--input", "--frames", "-o"];

/// Further options whose values are files, passed on in the extra arguments.
const PATHS: [&str; 5] = ["--mask", "--timing", "--stmap", "--stmap-a", "--stmap-b"];

impl Options {
    fn parse(args: &[String]) -> Result<Options, HostError> {
        let mut pairs = Vec::new();
        let mut rest = Vec::new();
        let mut args = args.iter();
        while let Some(arg) = args.next() {
            let (flag, inline) = match arg.split_once('=') {
                Some((f, v)) if f.starts_with('-') => (f, Some(v.to_owned())),
                _ => (arg.as_str(), None),
            };
            let flag = if flag == "--output" { "-o" } else { flag };
            if CARRIED.contains(&flag) {
                let value = match inline {
                    Some(v) => v,
                    None => args.next().cloned().ok_or_else(|| {
                        HostError::bad(format!("morphfx job openjd: {flag} needs a value"))
                    })?,
                };
                pairs.push((flag.to_owned(), value));
            } else if PATHS.contains(&flag) {
                // Workers start elsewhere: their files by absolute path.
                let value = match inline {
                    Some(v) => v,
                    None => args.next().cloned().ok_or_else(|| {
                        HostError::bad(format!("morphfx job openjd: {flag} needs a value"))
                    })?,
                };
                rest.push(flag.to_owned());
                rest.push(absolute(Path::new(&value))?);
            } else {
                rest.push(arg.clone());
            }
        }
        Ok(Options { pairs, rest })
    }

    /// The one value of `flag`, which the job needs.
    fn value(&self, flag: &str) -> Result<&str, HostError> {
        let mut found = self.pairs.iter().filter(|(f, _)| f == flag);
        match (found.next(), found.next()) {
            (Some((_, v)), None) => Ok(v),
            (None, _) => Err(HostError::bad(format!(
                "morphfx job openjd: the command needs {flag}{}",
                if flag == "--frames" {
                    " (a farm job renders a range of frames)"
                } else {
                    ""
                }
            ))),
            (Some(_), Some(_)) => Err(HostError::bad(format!(
                "morphfx job openjd: {flag} is given twice"
            ))),
        }
    }

    /// Everything else, as one string of words: refused where a word holds
    /// white space (the template splits the string there), or where the
    /// node would not take it (`--a` on a warp).
    fn extra(&self, inputs: &[(&str, &str)]) -> Result<String, HostError> {
        let wrong_input = self
            .pairs
            .iter()
            .find(|(f, _)| matches!(f.as_str(), "--a" | "--b" | "--input"))
            .filter(|(f, _)| !inputs.iter().any(|(i, _)| i == f));
        if let Some((flag, _)) = wrong_input {
            return Err(HostError::bad(format!(
                "morphfx job openjd: {flag} is not an option of this command"
            )));
        }
        if let Some(word) = self
            .rest
            .iter()
            .find(|w| w.chars().any(char::is_whitespace))
        {
            return Err(HostError::bad(format!(
                "morphfx job openjd: `{word}` holds white space, which the farm template's \
                 extra arguments split at: write it without"
            )));
        }
        Ok(self.rest.join(" "))
    }
}

/// `path` made absolute against the current folder, as a worker needs it,
/// with `.` and `..` folded away (by name: outputs need not exist yet).
fn absolute(path: &Path) -> Result<String, HostError> {
    use std::path::Component;
    let full = std::path::absolute(path)
        .map_err(|e| HostError::bad(format!("{}: {e}", path.display())))?;
    let mut folded = PathBuf::new();
    for part in full.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                folded.pop();
            }
            other => folded.push(other),
        }
    }
    Ok(folded.to_string_lossy().into_owned())
}

/// The morphfx command: a name on the workers' PATH stays as it is, a path
/// is made absolute.
fn command_path(command: &str) -> Result<String, HostError> {
    if command.contains('/') {
        absolute(Path::new(command))
    } else {
        Ok(command.to_owned())
    }
}

/// The folder holding the bundle `--bundle` names (the bundle, or its binary).
fn bundle_folder(bundle: &Path) -> PathBuf {
    bundle
        .ancestors()
        .find(|p| p.extension().is_some_and(|e| e == "bundle"))
        .and_then(Path::parent)
        .unwrap_or_else(|| bundle.parent().unwrap_or(Path::new(".")))
        .to_path_buf()
}
