//! One plugin instance as a host drives it: clips, params, the render
//! loop and the actions around it.

use std::ffi::{c_void, CStr, CString};
use std::sync::Arc;

use morphfx::geom::RectI;
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::param::*;

use super::bundle::{accept, failure, Bundle};
use super::effect::{Effect, FrameSource, Message};
use super::frame::{self, Frame};
use super::params::{self, ParamValue};
use super::planes;
use super::props::PropertySet;
use crate::error::HostError;
use crate::sync::Locked;

/// A new instance of `descriptor` in `context`: its params and clips copied
/// from the descriptor, the clips unconnected until a job connects them.
fn instance_effect(descriptor: &Effect, context: &str) -> Box<Effect> {
    let effect = Effect::new();
    for (k, v) in [
        (kOfxPropType, "OfxTypeImageEffectInstance"),
        (kOfxImageEffectPropContext, context),
    ] {
        effect.props.set_str(k, v);
    }
    effect
        .props
        .set_double(kOfxImageEffectPropFrameRate, &[24.0]);
    effect
        .props
        .set_double(kOfxImageEffectPropProjectPixelAspectRatio, &[1.0]);
    effect
        .props
        .set_ptr(kOfxPropInstanceData, std::ptr::null_mut());
    let desc_params = params::ParamSet::instance_of(&descriptor.params);
    *effect.params.params.locked() = std::mem::take(&mut *desc_params.params.locked());
    for name in descriptor.clip_names() {
        let desc_clip = descriptor.clip(&name).expect("listed");
        let clip = effect.add_clip(&name, desc_clip.props.clone_values());
        clip.props.set_int(kOfxImageClipPropConnected, &[0]);
        clip.props
            .set_str(kOfxImageClipPropFieldOrder, "OfxImageFieldNone");
        clip.props.set_double(kOfxImagePropPixelAspectRatio, &[1.0]);
        clip.props.set_double(kOfxImageEffectPropFrameRate, &[24.0]);
    }
    effect
}

impl Bundle {
    /// Loads, describes and instantiates plugin `id` in `context`.
    pub fn instance(&self, id: &str, context: &str) -> Result<Instance<'_>, HostError> {
        let info = self.plugins.iter().find(|p| p.id == id).ok_or_else(|| {
            HostError::bad(format!(
                "bundle {} has no plugin {id}",
                self.binary.display()
            ))
        })?;
        let plugin = info.plugin;
        self.send_load(plugin)?;
        let descriptor = self.describe(plugin, id, context)?;
        let effect = instance_effect(&descriptor, context);
        let st = self.call(
            plugin,
            kOfxActionCreateInstance,
            effect.handle() as *const c_void,
            None,
            None,
        );
        accept(st, "createInstance", &effect)?;
        Ok(Instance {
            bundle: self,
            plugin,
            _descriptor: descriptor,
            effect,
            spare: std::sync::Mutex::new(None),
        })
    }
}

/// One plugin instance with its clips and params.
pub struct Instance<'b> {
    bundle: &'b Bundle,
    plugin: *const OfxPlugin,
    _descriptor: Box<Effect>,
    pub effect: Box<Effect>,
    /// A rendered frame handed back ([`Self::recycle`]) for the next
    /// render of the same shape to write into.
    spare: std::sync::Mutex<Option<Frame>>,
}

/// A multi-planar plugin's answer to `GetClipComponents`.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipPlanes {
    /// Each clip's planes: those an input needs, those the output makes.
    pub needed: Vec<(String, Vec<String>)>,
    /// The clip planes not made pass through from.
    pub pass_through: Option<String>,
}

impl ClipPlanes {
    /// The planes `clip` needs (makes, for the output).
    pub fn needs(&self, clip: &str) -> Vec<String> {
        self.needed
            .iter()
            .find(|(c, _)| c == clip)
            .map(|(_, p)| p.clone())
            .unwrap_or_default()
    }
}

/// How the output image is laid out (for testing host variety).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputSpec {
    pub depth: &'static str,
    pub channels: usize,
    pub top_down: bool,
    pub render_scale: (f64, f64),
    /// Split the window into this many bands rendered concurrently.
    pub tiles: usize,
    /// Ask isIdentity first and copy the source it names, as hosts do
    /// (off: always render, to compare the plugin's own pixels).
    pub identity: bool,
    /// This host renders the sequence in frame order on this instance
    /// (kOfxImageEffectPropSequentialRenderStatus = 1).
    pub sequential: bool,
    /// A viewer's render while the instance is manipulated
    /// (kOfxImageEffectPropInteractiveRenderStatus = 1).
    pub interactive: bool,
    /// Host misuse: send this render window, whatever the output image
    /// covers (`None`: the image's bounds, in tiles).
    pub window: Option<RectI>,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            depth: "OfxBitDepthFloat",
            channels: 4,
            top_down: false,
            render_scale: (1.0, 1.0),
            tiles: 1,
            identity: true,
            sequential: false,
            interactive: false,
            window: None,
        }
    }
}

impl Instance<'_> {
    fn param(&self, name: &str) -> Result<&params::Param, HostError> {
        self.effect
            .params
            .get(name)
            .ok_or_else(|| HostError::bad(format!("the plugin has no param {name}")))
    }

    /// Which build of the plugin answers: its description ends with it, in
    /// brackets (a v3 build is about twice as fast as the baseline one, which
    /// a checkout without `cargo xtask bundle --release` runs).
    pub fn build_that_ran(&self) -> String {
        let text = self
            .descriptor_props()
            .str(openfx::sys::generic::core::kOfxPropPluginDescription)
            .unwrap_or_default();
        let build = text
            .rsplit_once('(')
            .map(|(_, b)| b.trim_end_matches(['.', ')']));
        build.unwrap_or("unnamed build").to_string()
    }

    /// The plugin's descriptor properties (what describe set).
    pub fn descriptor_props(&self) -> &PropertySet {
        &self._descriptor.props
    }

    pub fn param_names(&self) -> Vec<(String, String)> {
        self.effect.params.names()
    }

    pub fn param_props(&self, name: &str) -> Option<&PropertySet> {
        self.effect.params.get(name).map(|p| &p.props)
    }

    pub fn set_double(
        &self,
        name: &str,
        values: &[f64],
        time: Option<f64>,
    ) -> Result<(), HostError> {
        let p = self.param(name)?;
        let mut v = ParamValue::default();
        v.d[..values.len()].copy_from_slice(values);
        match time {
            Some(t) => p.set_key(t, v),
            None => p.set(v),
        }
        Ok(())
    }

    /// Tells the plugin to drop what it caches (`kOfxActionPurgeCaches`).
    pub fn purge_caches(&self) -> Result<(), HostError> {
        self.act(kOfxActionPurgeCaches, None, None).map(|_| ())
    }

    /// The messages the plugin posted since the last call (message suite).
    pub fn take_messages(&self) -> Vec<Message> {
        self.effect.take_messages()
    }

    /// The times of a param's keys, in order.
    pub fn key_times(&self, name: &str) -> Result<Vec<f64>, HostError> {
        Ok(self.param(name)?.key_times())
    }

    /// The values of a double-valued param at `time` (keys interpolated).
    pub fn doubles_at(&self, name: &str, time: f64) -> Result<Vec<f64>, HostError> {
        let p = self.param(name)?;
        let n = match p.shape() {
            params::Shape::Double(n) => n,
            _ => return Err(HostError::bad(format!("{name} is not a double param"))),
        };
        Ok(p.value_at(time).d[..n].to_vec())
    }

    /// The user will press cancel on the plugin's progress bar once it
    /// reaches `at` (`None`: never).
    pub fn cancel_progress_at(&self, at: Option<f64>) {
        *self.effect.cancel_at.locked() = at;
    }

    /// Every progress the plugin reported so far, and whether a progress
    /// task is still open.
    pub fn progress_log(&self) -> (Vec<f64>, bool) {
        let log = self.effect.progress_log.locked().clone();
        let open = self.effect.progress.locked().is_some();
        (log, open)
    }

    /// Tells the plugin the user changed (or pressed) param `name` at `time`.
    pub fn instance_changed(&self, name: &str, time: f64) -> Result<(), HostError> {
        *self.effect.render_scale.locked() = (1.0, 1.0);
        let name = CString::new(name).map_err(|_| HostError::bad("NUL in a param name"))?;
        let a = PropertySet::new();
        a.set_str(kOfxPropType, "OfxTypeParameter");
        a.set_str(kOfxPropName, &name.to_string_lossy());
        a.set_str(kOfxPropChangeReason, "OfxChangeUserEdited");
        a.set_double(kOfxPropTime, &[time]);
        a.set_double(kOfxImageEffectPropRenderScale, &[1.0, 1.0]);
        self.act(kOfxActionBeginInstanceChanged, Some(&a), None)?;
        let result = self.act(kOfxActionInstanceChanged, Some(&a), None);
        self.act(kOfxActionEndInstanceChanged, Some(&a), None)?;
        result.map(|_| ())
    }

    pub fn set_int(&self, name: &str, value: i32) -> Result<(), HostError> {
        let p = self.param(name)?;
        let mut v = ParamValue::default();
        v.i[0] = value;
        p.set(v);
        Ok(())
    }

    /// A string param's value.
    pub fn string(&self, name: &str) -> Result<String, HostError> {
        Ok(self
            .param(name)?
            .value_at(0.0)
            .s
            .to_string_lossy()
            .into_owned())
    }

    /// The persistent message the plugin has on the node (message suite
    /// v2), if any.
    pub fn persistent_message(&self) -> Option<String> {
        self.effect
            .persistent
            .locked()
            .as_ref()
            .map(|m| m.text.clone())
    }

    pub fn set_string(&self, name: &str, value: &str) -> Result<(), HostError> {
        let p = self.param(name)?;
        p.set(ParamValue {
            s: CString::new(value).map_err(|_| HostError::bad(format!("{name}: NUL in text")))?,
            ..Default::default()
        });
        Ok(())
    }

    /// Sets `name`'s option by its label (choice params).
    pub fn set_choice(&self, name: &str, option: &str) -> Result<(), HostError> {
        let i = self.choice_index(name, option)?;
        self.set_int(name, i as i32)
    }

    /// The index of choice param `name`'s option labelled `option` (or
    /// whose label starts with that word).
    pub fn choice_index(&self, name: &str, option: &str) -> Result<usize, HostError> {
        let p = self.param(name)?;
        let options = p.props.strs(kOfxParamPropChoiceOption);
        options
            .iter()
            .position(|o| o == option)
            .or_else(|| {
                options
                    .iter()
                    .position(|o| o.split(' ').next() == Some(option))
            })
            .ok_or_else(|| {
                HostError::bad(format!(
                    "{name}: unknown option \"{option}\" (one of {})",
                    options.join(", ")
                ))
            })
    }

    /// Sets an integer-valued param (integer, boolean, choice): constant,
    /// or keyed at `time` (keys hold until the next, as hosts step them).
    pub fn set_int_at(&self, name: &str, value: i32, time: Option<f64>) -> Result<(), HostError> {
        let p = self.param(name)?;
        let mut v = ParamValue::default();
        v.i[0] = value;
        match time {
            Some(t) => p.set_key(t, v),
            None => p.set(v),
        }
        Ok(())
    }

    pub fn connect(&self, clip: &str, source: Arc<dyn FrameSource>) -> Result<(), HostError> {
        let c = self
            .effect
            .clip(clip)
            .ok_or_else(|| HostError::bad(format!("the plugin has no clip {clip}")))?;
        if let Some((first, last)) = source.range() {
            c.props
                .set_double(kOfxImageEffectPropFrameRange, &[first, last]);
        }
        *c.source.locked() = Some(source);
        c.props.set_int(kOfxImageClipPropConnected, &[1]);
        Ok(())
    }

    /// Gives `clip` planes besides its colour (a multi-planar host's
    /// layers): `(plane string, source)` each, listed in the clip's
    /// planes-present property after the colour.
    pub fn connect_planes(
        &self,
        clip: &str,
        planes: Vec<(String, Arc<dyn FrameSource>)>,
    ) -> Result<(), HostError> {
        let c = self
            .effect
            .clip(clip)
            .ok_or_else(|| HostError::bad(format!("the plugin has no clip {clip}")))?;
        let mut present = vec![planes::COLOUR.to_owned()];
        present.extend(planes.iter().map(|(p, _)| p.clone()));
        let present: Vec<&str> = present.iter().map(String::as_str).collect();
        c.props.set_strs(planes::PLANES_PRESENT, &present);
        *c.planes.locked() = planes;
        Ok(())
    }

    /// The multi-plane extension's question: which planes each clip needs
    /// and the output makes at `time` (`NeededComp_<clip>`), and the clip
    /// the rest pass through from; `None` where the plugin leaves it to
    /// the host.
    pub fn clip_planes(&self, time: f64) -> Result<Option<ClipPlanes>, HostError> {
        let a = PropertySet::new();
        a.set_double(kOfxPropTime, &[time]);
        let out = PropertySet::new();
        if self.act(planes::GET_CLIP_COMPONENTS, Some(&a), Some(&out))? != kOfxStatOK {
            return Ok(None);
        }
        let needed = self
            .effect
            .clip_names()
            .into_iter()
            .map(|c| {
                let prop =
                    CString::new(format!("{}{c}", planes::NEEDED_PREFIX)).unwrap_or_default();
                let list = out.strs(&prop);
                (c, list)
            })
            .collect();
        let pass_through = out.strs(planes::PASS_THROUGH_CLIP).into_iter().next();
        Ok(Some(ClipPlanes {
            needed,
            pass_through,
        }))
    }

    /// Renders `planes` of frame `time` in one render action each window
    /// (the plugin asked for that, `RenderAllPlanes`), as a multi-planar
    /// host does: the colour plane laid out as `spec`, every other plane a
    /// float buffer of its own channel count. Each must be one the plugin
    /// said it makes.
    pub fn render_planes(
        &self,
        time: f64,
        spec: OutputSpec,
        asked: &[String],
    ) -> Result<Vec<(String, Arc<Frame>)>, HostError> {
        let made = self
            .clip_planes(time)?
            .map(|c| c.needs("Output"))
            .unwrap_or_else(|| vec![planes::COLOUR.to_owned()]);
        for p in asked {
            if !made.contains(p) {
                return Err(HostError::failed(format!(
                    "the plugin does not make plane {p} (it makes {})",
                    made.join(", ")
                )));
            }
        }
        let field = "OfxImageFieldNone";
        self.set_render_state(time, spec.render_scale, field);
        let bounds = self.output_bounds(time, spec.render_scale)?;
        let out_clip = self
            .effect
            .clip("Output")
            .ok_or_else(|| HostError::failed("the plugin has no Output clip"))?;
        let mut frames = Vec::new();
        for p in asked {
            let (channels, depth) = match p == planes::COLOUR {
                true => (spec.channels, spec.depth),
                false => (
                    planes::channels(p)
                        .ok_or_else(|| HostError::failed(format!("no such plane: {p}")))?,
                    "OfxBitDepthFloat",
                ),
            };
            let mut f = Frame::blank(bounds, channels, depth, spec.top_down);
            if cfg!(debug_assertions) {
                f.poison(); // as in `output_frame`
            }
            f.par = self.pixel_aspect();
            frames.push((p.clone(), Arc::new(f)));
        }
        // Every plane, colour too, only through the plane suite (Natron's way).
        *out_clip.output_planes.locked() = frames.clone();
        out_clip
            .props
            .set_str(kOfxImageEffectPropPixelDepth, spec.depth);
        let result = self.render_tiles(time, spec, field, bounds, asked);
        *out_clip.output.locked() = None;
        out_clip.output_planes.locked().clear();
        result?;
        Ok(frames)
    }

    /// Leaves `clip` unconnected, as a host does when its input is cut.
    pub fn disconnect(&self, clip: &str) -> Result<(), HostError> {
        let c = self
            .effect
            .clip(clip)
            .ok_or_else(|| HostError::bad(format!("the plugin has no clip {clip}")))?;
        *c.source.locked() = None;
        c.props.set_int(kOfxImageClipPropConnected, &[0]);
        Ok(())
    }

    /// Every param back to its default, unkeyed, as on a fresh instance:
    /// how a host reuses an instance for an unrelated render.
    pub fn reset_params(&self) {
        for p in self.effect.params.params.locked().iter() {
            p.reset();
        }
    }

    /// Anamorphic footage: pixels `par` canonical units wide, for the project
    /// and every clip (connect frames with the same `par`).
    pub fn set_pixel_aspect(&self, par: f64) {
        self.effect
            .props
            .set_double(kOfxImageEffectPropProjectPixelAspectRatio, &[par]);
        let clips = self.effect.clips.locked();
        for clip in clips.iter() {
            clip.props.set_double(kOfxImagePropPixelAspectRatio, &[par]);
        }
    }

    fn pixel_aspect(&self) -> f64 {
        let par = self
            .effect
            .props
            .doubles(kOfxImageEffectPropProjectPixelAspectRatio);
        par.first().copied().filter(|p| *p > 0.0).unwrap_or(1.0)
    }

    /// The project's images (size at offset), canonical, rounded out.
    fn project_rect(&self) -> RectI {
        let p = &self.effect.props;
        let (size, offset) = (
            p.doubles(kOfxImageEffectPropProjectSize),
            p.doubles(kOfxImageEffectPropProjectOffset),
        );
        let (w, h) = (
            size.first().copied().unwrap_or(0.0),
            size.get(1).copied().unwrap_or(0.0),
        );
        let (x, y) = (
            offset.first().copied().unwrap_or(0.0),
            offset.get(1).copied().unwrap_or(0.0),
        );
        RectI::new(
            x.floor() as i32,
            y.floor() as i32,
            (x + w).ceil() as i32,
            (y + h).ceil() as i32,
        )
    }

    pub fn set_project(&self, width: f64, height: f64) {
        self.set_letterboxed_project((width, height), (0.0, 0.0), (width, height));
    }

    /// A project whose images fill `size` at `offset` inside an `extent`
    /// rooted at 0,0 (a letterboxed format: the spec's project properties).
    pub fn set_letterboxed_project(
        &self,
        extent: (f64, f64),
        offset: (f64, f64),
        size: (f64, f64),
    ) {
        let p = &self.effect.props;
        p.set_double(kOfxImageEffectPropProjectExtent, &[extent.0, extent.1]);
        p.set_double(kOfxImageEffectPropProjectOffset, &[offset.0, offset.1]);
        p.set_double(kOfxImageEffectPropProjectSize, &[size.0, size.1]);
    }

    fn act(
        &self,
        action: &CStr,
        in_args: Option<&PropertySet>,
        out_args: Option<&PropertySet>,
    ) -> Result<OfxStatus, HostError> {
        let st = self.bundle.call(
            self.plugin,
            action,
            self.effect.handle() as *const c_void,
            in_args,
            out_args,
        );
        if st == kOfxStatOK || st == kOfxStatReplyDefault {
            Ok(st)
        } else {
            Err(failure(st, &action.to_string_lossy(), Some(&self.effect)))
        }
    }

    /// How many calls of the variadic value functions (get or set) the
    /// plugin made on param `name` so far.
    pub fn value_calls(&self, name: &str) -> usize {
        self.effect.params.get(name).map_or(0, |p| {
            p.value_calls.load(std::sync::atomic::Ordering::Relaxed)
        })
    }

    /// Sends `action` as a misbehaving host might (tests of the plugin's
    /// answers): with no effect handle when `null_handle`, and the
    /// arguments as given. The plugin's status, as it answered, and the
    /// messages it posted on the instance (its persistent one taken too).
    pub fn send_raw(
        &self,
        action: &CStr,
        null_handle: bool,
        in_args: Option<&PropertySet>,
        out_args: Option<&PropertySet>,
    ) -> (OfxStatus, Vec<Message>) {
        let handle = if null_handle {
            std::ptr::null()
        } else {
            self.effect.handle() as *const c_void
        };
        self.effect.take_messages();
        let status = self
            .bundle
            .call(self.plugin, action, handle, in_args, out_args);
        (status, self.messages_posted())
    }

    /// The messages the plugin posted on the instance since they were last
    /// taken, its persistent one taken too.
    fn messages_posted(&self) -> Vec<Message> {
        let mut messages = self.effect.take_messages();
        messages.extend(self.effect.persistent.locked().take());
        messages
    }

    /// Sends `action` on this instance through another plugin's main entry
    /// (`plugin`, an id of the same bundle), as a host that mixed up its
    /// handles would: the plugin's status and the messages it posted.
    pub fn send_via(
        &self,
        plugin: &str,
        action: &CStr,
        in_args: Option<&PropertySet>,
    ) -> Result<(OfxStatus, Vec<Message>), HostError> {
        let other = self
            .bundle
            .plugins
            .iter()
            .find(|p| p.id == plugin)
            .ok_or_else(|| HostError::bad(format!("no plugin {plugin} in the bundle")))?;
        self.effect.take_messages();
        let handle = self.effect.handle() as *const c_void;
        let status = self
            .bundle
            .call(other.plugin, action, handle, in_args, None);
        Ok((status, self.messages_posted()))
    }

    fn sequence_args(first: f64, last: f64) -> PropertySet {
        let a = PropertySet::new();
        a.set_double(kOfxImageEffectPropFrameRange, &[first, last]);
        a.set_double(kOfxImageEffectPropFrameStep, &[1.0]);
        a.set_int(kOfxPropIsInteractive, &[0]);
        a.set_double(kOfxImageEffectPropRenderScale, &[1.0, 1.0]);
        a
    }

    pub fn begin_sequence(&self, first: f64, last: f64) -> Result<(), HostError> {
        *self.effect.timeline.locked() = (first, first, last);
        let a = Self::sequence_args(first, last);
        self.act(kOfxImageEffectActionBeginSequenceRender, Some(&a), None)
            .map(|_| ())
    }

    pub fn end_sequence(&self, first: f64, last: f64) -> Result<(), HostError> {
        let a = Self::sequence_args(first, last);
        self.act(kOfxImageEffectActionEndSequenceRender, Some(&a), None)
            .map(|_| ())
    }

    /// The plugin's clip preferences (`kOfxImageEffectActionGetClipPreferences`),
    /// as hosts ask after connecting clips: the out-args it set. This host
    /// renders RGBA, so that is the output's default.
    pub fn clip_preferences(&self) -> Result<PropertySet, HostError> {
        self.clip_preferences_from("OfxImageComponentRGBA")
    }

    /// The same with the output's components defaulting to `output` (a
    /// host following RGB sources offers `OfxImageComponentRGB`).
    pub fn clip_preferences_from(&self, output: &str) -> Result<PropertySet, HostError> {
        let out = PropertySet::new();
        out.set_str(c"OfxImageClipPropComponents_Output", output);
        out.set_int(kOfxImageEffectFrameVarying, &[0]);
        out.set_str(
            kOfxImageEffectPropPreMultiplication,
            &kOfxImagePreMultiplied.to_string_lossy(),
        );
        self.act(kOfxImageEffectActionGetClipPreferences, None, Some(&out))?;
        Ok(out)
    }

    /// The output's region of definition at `time` (canonical): the
    /// plugin's, or where it replies default, the host's default.
    pub fn region_of_definition(&self, time: f64, scale: (f64, f64)) -> Result<RectI, HostError> {
        let a = PropertySet::new();
        a.set_double(kOfxPropTime, &[time]);
        a.set_double(kOfxImageEffectPropRenderScale, &[scale.0, scale.1]);
        let out = PropertySet::new();
        // The spec: the host sets the out-arg to the default first.
        let d = self.default_region(time);
        out.set_double(
            kOfxImageEffectPropRegionOfDefinition,
            &[d.x1 as f64, d.y1 as f64, d.x2 as f64, d.y2 as f64],
        );
        self.act(
            kOfxImageEffectActionGetRegionOfDefinition,
            Some(&a),
            Some(&out),
        )?;
        let r = out.doubles(kOfxImageEffectPropRegionOfDefinition);
        if r.len() != 4 {
            return Err(HostError::failed("the plugin gave no region of definition"));
        }
        Ok(RectI::new(
            r[0].floor() as i32,
            r[1].floor() as i32,
            r[2].ceil() as i32,
            r[3].ceil() as i32,
        ))
    }

    /// The spec's default region of definition, as for the filter,
    /// transition and general contexts: the union of the (non-optional)
    /// input clips' regions; this host gives an unconnected clip none, and
    /// with none at all the default is the project's.
    fn default_region(&self, time: f64) -> RectI {
        let clips = self.effect.clips.locked();
        clips
            .iter()
            .filter(|c| c.name != "Output")
            .filter(|c| c.props.ints(kOfxImageClipPropOptional).first() != Some(&1))
            .filter_map(|c| c.rod(time))
            .reduce(|u, r| {
                RectI::new(
                    u.x1.min(r.x1),
                    u.y1.min(r.y1),
                    u.x2.max(r.x2),
                    u.y2.max(r.y2),
                )
            })
            .unwrap_or_else(|| self.project_rect())
    }

    /// Asks the plugin whether the output at `time` is one of its sources
    /// unchanged (`kOfxImageEffectActionIsIdentity`), as hosts do before
    /// rendering: `Some((clip, time))` when it is.
    pub fn identity(
        &self,
        time: f64,
        window: RectI,
        scale: (f64, f64),
    ) -> Result<Option<(String, f64)>, HostError> {
        let a = PropertySet::new();
        a.set_double(kOfxPropTime, &[time]);
        a.set_str(kOfxImageEffectPropFieldToRender, "OfxImageFieldNone");
        a.set_int(
            kOfxImageEffectPropRenderWindow,
            &[window.x1, window.y1, window.x2, window.y2],
        );
        a.set_double(kOfxImageEffectPropRenderScale, &[scale.0, scale.1]);
        let out = PropertySet::new();
        out.set_str(kOfxPropName, "");
        out.set_double(kOfxPropTime, &[time]);
        if self.act(kOfxImageEffectActionIsIdentity, Some(&a), Some(&out))? != kOfxStatOK {
            return Ok(None);
        }
        let name = out
            .strs(kOfxPropName)
            .into_iter()
            .next()
            .unwrap_or_default();
        let at = out.doubles(kOfxPropTime).first().copied().unwrap_or(time);
        if self.effect.clip(&name).is_none() || name == "Output" {
            return Err(HostError::failed(format!(
                "isIdentity named clip \"{name}\", which is not one of the plugin's source clips"
            )));
        }
        Ok(Some((name, at)))
    }

    /// Renders the frame at `time` into a new buffer laid out as `spec`,
    /// or copies the source the plugin names as identical.
    /// Interlaced footage, `order` (`OfxImageFieldLower` or `Upper`) first:
    /// renders then go field by field as the plugin asks.
    pub fn set_field_order(&self, order: &'static str) {
        *self.effect.field_order.locked() = Some(order);
        let clips = self.effect.clips.locked();
        for clip in clips.iter() {
            clip.props.set_str(kOfxImageClipPropFieldOrder, order);
        }
    }

    /// Renders frame `time`. Interlaced footage goes as the spec says: with
    /// `FieldRenderTwiceAlways` (the default), once per field, the first at
    /// `time` and the second at `time + 0.5`, each from single-field sources
    /// with lines doubled, the output interleaving the two; otherwise once,
    /// both fields at a time (this host animates nothing it renders).
    pub fn render(&self, time: f64, spec: OutputSpec) -> Result<Arc<Frame>, HostError> {
        let order = *self.effect.field_order.locked();
        let Some(first) = order else {
            return self.render_field(time, spec, "OfxImageFieldNone");
        };
        let twice = self
            .descriptor_props()
            .ints(kOfxImageEffectPluginPropFieldRenderTwiceAlways)
            .first()
            .is_none_or(|v| *v != 0);
        if !twice {
            return self.render_field(time, spec, "OfxImageFieldBoth");
        }
        let second = if first == "OfxImageFieldLower" {
            "OfxImageFieldUpper"
        } else {
            "OfxImageFieldLower"
        };
        let a = self.render_field(time, spec, first)?.to_image();
        let b = self.render_field(time + 0.5, spec, second)?.to_image();
        *self.effect.field.locked() = "OfxImageFieldNone";
        let upper_first = first == "OfxImageFieldUpper";
        let both = morphfx::image::Image::from_fn(a.bounds, a.channels, |i, j, c| {
            let upper = j.rem_euclid(2) == 1;
            if upper == upper_first {
                a.pixel(i, j)[c]
            } else {
                b.pixel(i, j)[c]
            }
        });
        let mut out = Frame::from_image(&both, spec.depth, spec.top_down);
        out.par = self.pixel_aspect();
        Ok(Arc::new(out))
    }

    fn render_field(
        &self,
        time: f64,
        spec: OutputSpec,
        field: &'static str,
    ) -> Result<Arc<Frame>, HostError> {
        self.set_render_state(time, spec.render_scale, field);
        let bounds = self.output_bounds(time, spec.render_scale)?;
        if spec.identity {
            if let Some((clip, at)) = self.identity(time, bounds, spec.render_scale)? {
                return Ok(self.pass_through(&clip, at, bounds, spec));
            }
        }
        let mut out = self.output_frame(bounds, spec);
        out.par = self.pixel_aspect();
        let out = Arc::new(out);
        let out_clip = self
            .effect
            .clip("Output")
            .ok_or_else(|| HostError::failed("the plugin has no Output clip"))?;
        *out_clip.output.locked() = Some(out.clone());
        out_clip
            .props
            .set_str(kOfxImageEffectPropPixelDepth, spec.depth);
        let result = self.render_tiles(time, spec, field, bounds, &[]);
        *out_clip.output.locked() = None;
        result?;
        Ok(out)
    }

    /// Hands a rendered frame back, done with, for the next render of the
    /// same shape to write into, as a host's viewer reuses its buffers: a
    /// fresh buffer, zeroed and faulted in page by page, cost 11–25 % of an
    /// unchanged 1080p frame's time and half a UHD one's
    /// (docs/PERFORMANCE.md). A frame still shared elsewhere is only
    /// dropped.
    pub fn recycle(&self, frame: Arc<Frame>) {
        if let Ok(f) = Arc::try_unwrap(frame) {
            *self.spare.locked() = Some(f);
        }
    }

    /// The buffer a render's output is written into: the frame last handed
    /// back ([`Self::recycle`]) when its shape is the same, else a fresh one.
    ///
    /// Its pixels are what the plugin must write in full: the spec leaves
    /// an output image's contents before a render undefined. Debug builds
    /// (the tests') fill every output buffer with NaN or the integer
    /// depths' largest value first, so a pixel a plugin leaves unwritten
    /// shows up as that, not as black or as an earlier render's pixel.
    fn output_frame(&self, bounds: RectI, spec: OutputSpec) -> Frame {
        let spare = self.spare.locked().take();
        let mut frame = spare
            .filter(|f| {
                f.bounds == bounds
                    && f.channels == spec.channels
                    && f.depth() == spec.depth
                    && f.top_down == spec.top_down
            })
            .unwrap_or_else(|| Frame::blank(bounds, spec.channels, spec.depth, spec.top_down));
        frame.premultiplied = true;
        if cfg!(debug_assertions) {
            frame.poison();
        }
        frame
    }

    /// What the plugin may ask the host during a render: the field, the
    /// time on the timeline and the render scale.
    fn set_render_state(&self, time: f64, scale: (f64, f64), field: &'static str) {
        *self.effect.field.locked() = field;
        self.effect.take_messages();
        self.effect.timeline.locked().0 = time;
        *self.effect.render_scale.locked() = scale;
    }

    /// The pixels to render: the region of definition at `scale` (the
    /// project where it is infinite, as a viewer shows it).
    fn output_bounds(&self, time: f64, scale: (f64, f64)) -> Result<RectI, HostError> {
        let rod = self.region_of_definition(time, scale)?;
        let rod = if rod.x1 <= i32::MIN / 2 || rod.x2 >= i32::MAX / 2 {
            rod.intersect(&self.project_rect())
        } else {
            rod
        };
        // Pixels: canonical x divided by the pixel aspect ratio.
        let par = self.pixel_aspect();
        let (sx, sy) = scale;
        Ok(RectI::new(
            (rod.x1 as f64 * sx / par).floor() as i32,
            (rod.y1 as f64 * sy).floor() as i32,
            (rod.x2 as f64 * sx / par).ceil() as i32,
            (rod.y2 as f64 * sy).ceil() as i32,
        ))
    }

    /// An identity render: the clip's frame at `at`, as the host copies it.
    fn pass_through(&self, clip: &str, at: f64, bounds: RectI, spec: OutputSpec) -> Arc<Frame> {
        let source = self
            .effect
            .clip(clip)
            .and_then(|c| c.frame_at(at).ok().flatten());
        let image = match source {
            Some(f) => frame::with_channels(&f.to_image(), spec.channels),
            None => morphfx::image::Image::new(bounds, spec.channels),
        };
        Arc::new(Frame::from_image(&image, spec.depth, spec.top_down))
    }

    /// The render action over `spec.tiles` horizontal bands of `bounds`,
    /// each on its own thread as a multi-threaded host would.
    fn render_tiles(
        &self,
        time: f64,
        spec: OutputSpec,
        field: &'static str,
        bounds: RectI,
        planes: &[String],
    ) -> Result<(), HostError> {
        let tiles = spec.tiles.max(1) as i32;
        let band = (bounds.height() as i32 + tiles - 1) / tiles;
        let windows: Vec<RectI> = (0..tiles)
            .map(|k| {
                RectI::new(
                    bounds.x1,
                    bounds.y1 + k * band,
                    bounds.x2,
                    (bounds.y1 + (k + 1) * band).min(bounds.y2),
                )
            })
            .filter(|w| !w.is_empty())
            .collect();
        let (sx, sy) = spec.render_scale;
        let render_one = |w: RectI| {
            let a = PropertySet::new();
            a.set_double(kOfxPropTime, &[time]);
            a.set_str(kOfxImageEffectPropFieldToRender, field);
            a.set_int(kOfxImageEffectPropRenderWindow, &[w.x1, w.y1, w.x2, w.y2]);
            a.set_double(kOfxImageEffectPropRenderScale, &[sx, sy]);
            a.set_int(
                kOfxImageEffectPropSequentialRenderStatus,
                &[spec.sequential as i32],
            );
            a.set_int(
                kOfxImageEffectPropInteractiveRenderStatus,
                &[spec.interactive as i32],
            );
            if !planes.is_empty() {
                let planes: Vec<&str> = planes.iter().map(String::as_str).collect();
                a.set_strs(planes::RENDER_PLANES, &planes);
            }
            self.act(kOfxImageEffectActionRender, Some(&a), None)
                .map(|_| ())
        };
        if let Some(w) = spec.window {
            return render_one(w);
        }
        if windows.len() == 1 {
            return render_one(windows[0]);
        }
        std::thread::scope(|s| {
            let handles: Vec<_> = windows
                .iter()
                .map(|w| s.spawn(move || render_one(*w)))
                .collect();
            handles.into_iter().try_for_each(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(HostError::failed("render thread panicked")))
            })
        })
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        let _ = self.bundle.call(
            self.plugin,
            kOfxActionDestroyInstance,
            self.effect.handle() as *const c_void,
            None,
            None,
        );
    }
}

// SAFETY: an instance's host state is behind its own locks, and the plugin
// declares its renders fully thread safe.
unsafe impl Sync for Instance<'_> {}
// SAFETY: OFX lets a host call an instance's actions from any thread (Nuke
// and Natron do); what the instance holds is its host state (behind its
// locks) and pointers into the loaded bundle, which outlives it.
unsafe impl Send for Instance<'_> {}
