//! `--line N=...` and `--line N@FRAME=...`: line slots keyed as a host would.

use crate::host::HostError;

/// One `--line` value: slot, optional key frame, A start/end then B start/end.
pub struct LineKey {
    pub slot: usize,
    pub frame: Option<f64>,
    pub coords: [f64; 8],
}

impl LineKey {
    /// The nodes' line slots (Line Count at most).
    const SLOTS: usize = 64;

    pub fn parse(spec: &str) -> Result<LineKey, HostError> {
        let bad = |why: &str| {
            HostError::bad(format!(
                "--line {spec}: {why} (expected N=ax0,ay0,ax1,ay1,bx0,by0,bx1,by1 or N@FRAME=...)"
            ))
        };
        let (head, values) = spec.split_once('=').ok_or_else(|| bad("no '='"))?;
        let (slot, frame) = match head.split_once('@') {
            Some((n, f)) => (
                n,
                Some(f.trim().parse::<f64>().map_err(|_| bad("bad frame"))?),
            ),
            None => (head, None),
        };
        let slot: usize = slot.trim().parse().map_err(|_| bad("bad slot number"))?;
        if !(1..=Self::SLOTS).contains(&slot) {
            return Err(bad(&format!("slot must be 1 to {}", Self::SLOTS)));
        }
        let numbers: Vec<f64> = values
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad("bad number"))?;
        let coords: [f64; 8] = numbers
            .try_into()
            .map_err(|_| bad("needs exactly 8 numbers"))?;
        if coords.iter().any(|v| !v.is_finite()) || frame.is_some_and(|f| !f.is_finite()) {
            return Err(bad("numbers must be finite"));
        }
        Ok(LineKey {
            slot,
            frame,
            coords,
        })
    }
}
