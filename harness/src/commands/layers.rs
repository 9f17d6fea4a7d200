//! `morphfx warp --layers`: every chosen layer of a multi-layer EXR through
//! the same warp. The layers go through the Warp node four channels at a
//! time (a channel group travels as one RGBA picture, its channels filtered
//! independently), with the maps the node made once; layers that hold IDs
//! or mattes are sampled nearest, so no ID is blended into another.

use std::sync::Arc;

use openfx::sys::image_effect_v1::param::kOfxParamPropChoiceOption;

use crate::error::HostError;
use crate::host::{Frame, Instance, OutputSpec};
use crate::io::OutputFormat;
use crate::layered::{holds_ids, Layer, Layered, RGBA};
use crate::plates::Still;
use crate::progress::Progress;
use crate::sequence::{frame_path, is_sequence};

/// Which layers a run warps: `--layers` and `--id-layers`.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerChoice {
    /// `None`: every layer.
    pub names: Option<Vec<String>>,
    /// Layers sampled nearest besides those [`holds_ids`] finds.
    pub ids: Vec<String>,
}

fn list(spec: &str) -> Vec<String> {
    spec.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(str::to_owned)
        .collect()
}

impl LayerChoice {
    /// `--layers SPEC --id-layers IDS`; `None` for the main picture alone
    /// (`rgba`), which renders as any warp does.
    pub fn parse(spec: &str, ids: &str) -> Result<Option<LayerChoice>, HostError> {
        let names = match spec.trim() {
            RGBA => return Ok(None),
            "all" => None,
            other => Some(list(other)),
        };
        if names.as_ref().is_some_and(Vec::is_empty) {
            return Err(HostError::bad(format!(
                "--layers {spec:?}: expected rgba, all or a list of layer names"
            )));
        }
        Ok(Some(LayerChoice {
            names,
            ids: list(ids),
        }))
    }

    /// The chosen layers of `file`'s `layers`, in the file's order.
    fn pick(&self, layers: Vec<Layer>, file: &str) -> Result<Vec<Layer>, HostError> {
        let Some(names) = &self.names else {
            return Ok(layers);
        };
        for name in names {
            if !layers.iter().any(|l| &l.name == name) {
                let have: Vec<&str> = layers.iter().map(|l| l.name.as_str()).collect();
                return Err(HostError::bad(format!(
                    "--layers {name}: {file} has no such layer (it has {})",
                    have.join(", ")
                )));
            }
        }
        Ok(layers
            .into_iter()
            .filter(|l| names.contains(&l.name))
            .collect())
    }

    fn nearest(&self, layer: &str) -> bool {
        holds_ids(layer) || self.ids.iter().any(|n| n == layer)
    }
}

/// What a layered run renders: the input and output patterns, the frames
/// and how the output is written.
pub struct LayeredRun<'a> {
    pub input: &'a str,
    pub output: &'a str,
    pub frames: &'a [i64],
    pub format: OutputFormat,
    /// The warp moves from frame to frame: caches go after each.
    pub purge: bool,
}

/// The option the Filter param holds at `time`, as the user set it.
fn filter_at(inst: &Instance<'_>, time: f64) -> Result<String, HostError> {
    let param = inst
        .effect
        .params
        .get("filter")
        .ok_or_else(|| HostError::failed("the Warp node has no Filter param"))?;
    let options = param.props.strs(kOfxParamPropChoiceOption);
    let k = param.value_at(time).i[0];
    usize::try_from(k)
        .ok()
        .and_then(|k| options.get(k).cloned())
        .ok_or_else(|| HostError::failed(format!("the Filter param holds option {k}")))
}

/// Checks what a layered run needs of the command line before anything is
/// read: EXR in and out, the picture view, no extra outputs.
pub fn check(input: &str, output: &str, view: &str, extra: usize) -> Result<(), HostError> {
    for (what, path) in [("input", input), ("output", output)] {
        if !path.to_ascii_lowercase().ends_with(".exr") {
            return Err(HostError::bad(format!(
                "--layers: the {what} {path} must be an EXR (layers live in EXRs)"
            )));
        }
    }
    if view != "warped" {
        return Err(HostError::bad(format!(
            "--layers warps pictures: --view {view} takes no layers (leave --layers out)"
        )));
    }
    if extra > 0 {
        return Err(HostError::bad(
            "--layers with --stmap: write the ST map in a run of its own",
        ));
    }
    Ok(())
}

impl LayeredRun<'_> {
    /// Renders every frame on `inst` (its params and mattes set, its view
    /// the picture): each chosen layer warped, all written to one EXR.
    pub fn render(&self, inst: &Instance<'_>, choice: &LayerChoice) -> Result<(), HostError> {
        let progress = Progress::new(self.frames.len());
        for (n, &f) in self.frames.iter().enumerate() {
            let filter = filter_at(inst, f as f64)?;
            let file = frame_path(self.input, if is_sequence(self.input) { f } else { 0 });
            let plate = Layered::read(&file)?;
            let layers = choice.pick(plate.layers(), &file.display().to_string())?;
            let mut channels = Vec::new();
            let mut bounds = None;
            for layer in &layers {
                let filter = if choice.nearest(&layer.name) {
                    "nearest"
                } else {
                    &filter
                };
                inst.set_choice("filter", filter)?;
                for group in layer.channels.chunks(4) {
                    let source = Frame::from_float_image(plate.group(group));
                    inst.connect("Source", Arc::new(Still(Arc::new(source))))?;
                    let spec = OutputSpec {
                        sequential: true,
                        ..OutputSpec::default()
                    };
                    let out = inst.render(f as f64, spec)?.into_image();
                    let planes = out.data.chunks_exact(4);
                    for (c, &k) in group.iter().enumerate() {
                        let plane = planes.clone().map(|px| px[c]).collect();
                        channels.push((plate.channels[k].0.clone(), plane));
                    }
                    bounds = Some(out.bounds);
                }
            }
            let out = Layered {
                bounds: bounds.unwrap_or(plate.bounds),
                channels,
                ..plate
            };
            out.write(
                &frame_path(self.output, f),
                self.format.precision,
                self.format.compression,
            )?;
            if self.purge {
                inst.purge_caches()?;
            }
            progress.tick(n + 1, f);
        }
        progress.done("layers warped");
        Ok(())
    }
}
