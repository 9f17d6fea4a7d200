//! `morphfx overlay`: a node's viewer overlay drawn over the plates.

use std::path::Path;

use super::job::{morph_job, Job, Prepared, WARP_ID};
use crate::cli::Common;
use crate::host::overlay::Overlay;
use crate::host::{Bundle, HostError, HostOptions, Instance};
use crate::io::{self};
use crate::progress::Progress;
use crate::sequence::frame_path;

/// `morphfx overlay`: the Morph node's overlay with A and B, else the Warp
/// node's with its input.
pub fn overlay_job(
    common: Common,
    a: Option<String>,
    b: Option<String>,
    input: Option<String>,
) -> Result<Job, HostError> {
    match (a, b, input) {
        (Some(a), Some(b), None) => {
            morph_job(common, a, b, [None, None], "morph".into(), "general")
        }
        (None, None, Some(input)) => Ok(Job {
            plugin: WARP_ID,
            context: "OfxImageEffectContextFilter",
            sources: vec![("Source".to_owned(), input)],
            view: "warped".into(),
            extra: Vec::new(),
            mattes: Vec::new(),
            common,
            layers: None,
        }),
        _ => Err(HostError::bad(
            "overlay needs --a and --b (Morph) or --input (Warp)",
        )),
    }
}

/// The Show Lines option `--show` names.
pub fn show_option(show: &str) -> Result<&'static str, HostError> {
    Ok(match show {
        "both" => "A and B",
        "a" => "A only",
        "b" => "B only",
        "between" => "in-between",
        other => {
            return Err(HostError::bad(format!(
                "--show {other}: expected a, b, both or between"
            )))
        }
    })
}

impl Job {
    /// `morphfx overlay`: the plugin's overlay drawn over the plates.
    pub fn run_overlay(&self, bundle_path: &Path, show: &str) -> Result<(), HostError> {
        show_option(show)?;
        let job = self.prepare()?;
        let options = HostOptions {
            overlays: true,
            draw_suite: true,
            multi_plane: false,
        };
        let bundle = Bundle::load_with(bundle_path, options)?;
        let inst = bundle.instance(self.plugin, self.context)?;
        self.set_up(&inst, &job)?;
        if self.common.scene.is_some() {
            // As a compositor does to edit a scene file's shapes: they are
            // then drawn as the node draws shapes it owns (control points
            // marked, full strength) rather than dimmed.
            let first = job.frames.first().copied().unwrap_or(0) as f64;
            inst.instance_changed("copy_scene", first)?;
        }
        self.draw_overlays(&inst, &job, show)
    }

    /// Each frame's plate (B's with `--show b`, else the first source's)
    /// with the overlay drawn on it, written where the output says.
    pub fn draw_overlays(
        &self,
        inst: &Instance<'_>,
        job: &Prepared,
        show: &str,
    ) -> Result<(), HostError> {
        inst.set_choice("overlay_show", show_option(show)?)?;
        let drawn_on = match (show, self.sources.len()) {
            ("b", 2) => 1,
            _ => 0,
        };
        let overlay = Overlay::new(inst, true)?
            .ok_or_else(|| HostError::failed("the plugin declares no overlay"))?;
        let format = self.common.output_format(&job.inputs)?;
        let progress = Progress::new(job.frames.len());
        for (n, &f) in job.frames.iter().enumerate() {
            // Every source is read, the one not drawn on too: a damaged
            // input is refused whichever plate the overlay shows.
            let mut plates = self
                .sources
                .iter()
                .map(|(_, p)| io::read_as(&frame_path(p, f), format.colour))
                .collect::<Result<Vec<_>, _>>()?;
            let mut plate = plates.swap_remove(drawn_on);
            let calls = overlay.draw(f as f64, (1.0, 1.0))?;
            crate::raster::paint(&mut plate.image, &calls, (1.0, 1.0));
            io::write_as(&frame_path(&self.common.output, f), &plate, format)?;
            progress.tick(n + 1, f);
        }
        progress.done("overlays drawn");
        Ok(())
    }
}
