//! `--param ID=VALUE` and `--param ID@FRAME=VALUE`: any node param set by
//! its id, as a host's param panel would, and `morphfx params`, which lists
//! them.

use openfx::sys::image_effect_v1::param::*;

use crate::host::{HostError, Instance};

/// One `--param` value: the param's id, the frame it is keyed at (`None`:
/// a constant), and the value as written.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSetting {
    pub id: String,
    pub frame: Option<f64>,
    pub value: String,
}

/// Params the command line drives itself: set them through its own options.
const DRIVEN: &[(&str, &str)] = &[
    ("view", "--view"),
    ("Transition", "--t or the scene's progress keys"),
];

impl ParamSetting {
    pub fn parse(spec: &str) -> Result<ParamSetting, HostError> {
        let bad = |why: &str| {
            HostError::bad(format!(
                "--param {spec}: {why} (expected ID=VALUE or ID@FRAME=VALUE)"
            ))
        };
        let (head, value) = spec.split_once('=').ok_or_else(|| bad("no '='"))?;
        let (id, frame) = match head.split_once('@') {
            Some((id, f)) => {
                let f: f64 = f.trim().parse().map_err(|_| bad("bad frame"))?;
                if !f.is_finite() {
                    return Err(bad("bad frame"));
                }
                (id, Some(f))
            }
            None => (head, None),
        };
        let id = id.trim();
        if id.is_empty() {
            return Err(bad("no param id"));
        }
        Ok(ParamSetting {
            id: id.to_owned(),
            frame,
            value: value.to_owned(),
        })
    }

    /// Sets the param on `inst` as a host would: the value checked against
    /// the param's type and range, keyed at the frame when one is given.
    pub fn apply(&self, inst: &Instance<'_>) -> Result<(), HostError> {
        let at = match self.frame {
            Some(f) => format!("{}@{f}", self.id),
            None => self.id.clone(),
        };
        let bad = |why: String| HostError::bad(format!("--param {at}={}: {why}", self.value));
        if let Some((_, option)) = DRIVEN.iter().find(|(id, _)| *id == self.id) {
            return Err(bad(format!("set by {option}")));
        }
        let props = inst.param_props(&self.id).ok_or_else(|| {
            bad(format!(
                "the node has no param {} (`morphfx params` lists them)",
                self.id
            ))
        })?;
        let kind = props.str(kOfxParamPropType).unwrap_or_default();
        if self.frame.is_some() && props.ints(kOfxParamPropAnimates).first() == Some(&0) {
            return Err(bad(format!("{} cannot be animated", self.id)));
        }
        let v = self.value.trim();
        match kind.as_str() {
            "OfxParamTypeDouble" | "OfxParamTypeDouble2D" => {
                let n = if kind.ends_with("2D") { 2 } else { 1 };
                let values: Vec<f64> = v
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad(format!("expected {n} number(s)")))?;
                if values.len() != n || values.iter().any(|x| !x.is_finite()) {
                    return Err(bad(format!("expected {n} finite number(s), as x,y for 2D")));
                }
                let (lo, hi) = (
                    props.doubles(kOfxParamPropMin),
                    props.doubles(kOfxParamPropMax),
                );
                for (k, x) in values.iter().enumerate() {
                    let (lo, hi) = (lo.get(k).copied(), hi.get(k).copied());
                    if lo.is_some_and(|lo| *x < lo) || hi.is_some_and(|hi| *x > hi) {
                        return Err(bad(format!(
                            "out of range [{}, {}]",
                            lo.unwrap_or(f64::NEG_INFINITY),
                            hi.unwrap_or(f64::INFINITY)
                        )));
                    }
                }
                inst.set_double(&self.id, &values, self.frame)
            }
            "OfxParamTypeInteger" => {
                let x: i32 = v.parse().map_err(|_| bad("expected an integer".into()))?;
                let lo = props.ints(kOfxParamPropMin).first().copied();
                let hi = props.ints(kOfxParamPropMax).first().copied();
                if lo.is_some_and(|lo| x < lo) || hi.is_some_and(|hi| x > hi) {
                    return Err(bad(format!(
                        "out of range [{}, {}]",
                        lo.unwrap_or(i32::MIN),
                        hi.unwrap_or(i32::MAX)
                    )));
                }
                inst.set_int_at(&self.id, x, self.frame)
            }
            "OfxParamTypeBoolean" => {
                let on = match v {
                    "true" => 1,
                    "false" => 0,
                    _ => return Err(bad("expected true or false".into())),
                };
                inst.set_int_at(&self.id, on, self.frame)
            }
            "OfxParamTypeChoice" => {
                let k = inst.choice_index(&self.id, v)?;
                inst.set_int_at(&self.id, k as i32, self.frame)
            }
            "OfxParamTypeString" => {
                if self.frame.is_some() {
                    return Err(bad("text params are not keyed here".into()));
                }
                inst.set_string(&self.id, &self.value)
            }
            other => Err(bad(format!(
                "{} is a {} param, which holds no value",
                self.id,
                other.trim_start_matches("OfxParamType")
            ))),
        }
    }
}

/// One line per param of `inst`: id, type, default, range or options, and
/// whether it animates; groups and pages are left out.
pub fn param_lines(inst: &Instance<'_>) -> Vec<String> {
    let mut lines = vec![format!(
        "{:<24} {:<9} {:<30} {:<40} {}",
        "ID", "TYPE", "DEFAULT", "RANGE OR OPTIONS", "LABEL"
    )];
    let mut slots = 0;
    for (id, kind) in inst.param_names() {
        let Some(p) = inst.param_props(&id) else {
            continue;
        };
        // The line slots repeat one block of params: slot 1 is listed, the
        // rest said in one line after it.
        match line_slot(&id) {
            Some(1) | None => {}
            Some(k) => {
                slots = slots.max(k);
                continue;
            }
        }
        let short = kind.trim_start_matches("OfxParamType");
        let (default, range) = match short {
            "Double" | "Double2D" => {
                let join = |v: Vec<f64>| {
                    v.iter()
                        .map(|x| x.to_string())
                        .collect::<Vec<_>>()
                        .join(",")
                };
                (
                    join(p.doubles(kOfxParamPropDefault)),
                    format!(
                        "[{}, {}]",
                        join(p.doubles(kOfxParamPropMin)),
                        join(p.doubles(kOfxParamPropMax))
                    ),
                )
            }
            "Integer" => (
                p.ints(kOfxParamPropDefault)
                    .first()
                    .map_or(String::new(), |v| v.to_string()),
                format!(
                    "[{}, {}]",
                    p.ints(kOfxParamPropMin)
                        .first()
                        .copied()
                        .unwrap_or(i32::MIN),
                    p.ints(kOfxParamPropMax)
                        .first()
                        .copied()
                        .unwrap_or(i32::MAX)
                ),
            ),
            "Boolean" => (
                (p.ints(kOfxParamPropDefault).first() == Some(&1)).to_string(),
                "true|false".into(),
            ),
            "Choice" => {
                let options = p.strs(kOfxParamPropChoiceOption);
                let d = p.ints(kOfxParamPropDefault).first().copied().unwrap_or(0);
                (
                    options.get(d as usize).cloned().unwrap_or_default(),
                    options.join("|"),
                )
            }
            "String" => (
                format!("{:?}", p.str(kOfxParamPropDefault).unwrap_or_default()),
                "text".into(),
            ),
            _ => continue, // groups, pages and buttons hold no value
        };
        let animates = p.ints(kOfxParamPropAnimates).first() != Some(&0) && short != "String";
        let label = p
            .str(openfx::sys::generic::core::kOfxPropLabel)
            .unwrap_or_default();
        let range = if animates {
            format!("{range} (animates)")
        } else {
            range
        };
        lines.push(format!(
            "{id:<24} {short:<9} {default:<30} {range:<40} {label}"
        ));
    }
    if slots > 1 {
        let at = lines
            .iter()
            .rposition(|l| line_slot(l.split(' ').next().unwrap_or("")) == Some(1))
            .map_or(lines.len(), |k| k + 1);
        lines.insert(
            at,
            format!("line2_... to line{slots}_...: as line1_..., one block per line slot"),
        );
    }
    lines
}

/// The line slot a param id belongs to (`line12_a_start`: 12).
fn line_slot(id: &str) -> Option<usize> {
    let rest = id.strip_prefix("line")?;
    let (k, _) = rest.split_once('_')?;
    k.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_with_and_without_a_frame() {
        let p = ParamSetting::parse("mix@1012=0.25").unwrap();
        assert_eq!(
            (p.id.as_str(), p.frame, p.value.as_str()),
            ("mix", Some(1012.0), "0.25")
        );
        let p = ParamSetting::parse("scene_text={\"a\": 1}").unwrap();
        assert_eq!((p.frame, p.value.as_str()), (None, "{\"a\": 1}"));
        for bad in ["mix", "=1", "mix@x=1", "mix@inf=1"] {
            assert!(ParamSetting::parse(bad).is_err(), "{bad}");
        }
    }
}
