//! What this layer keeps on an instance (`kOfxPropInstanceData`): the node
//! the instance was made as, shared by every action that runs while it lives.

use std::any::Any;
use std::ffi::c_void;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use openfx::sys::generic::core::*;

use super::clips::EffectHandle;
use super::plugin::ImageEffect;
use super::{Failure, Outcome};

/// What the layer keeps on an instance: the node, and whether its
/// persistent error is showing.
pub(super) struct Attached {
    node: Box<dyn Any + Send + Sync>,
    pub(super) error_shown: AtomicBool,
}

impl Attached {
    /// The node, as the type whose entry point asks: an instance of another
    /// plugin (a host that mixed up handles) is an error, never a cast.
    pub(super) fn node<E: ImageEffect>(&self) -> Outcome<&E> {
        self.node.downcast_ref::<E>().ok_or_else(|| {
            Failure::Status(
                kOfxStatErrBadHandle,
                format!("the instance is not a {} node", E::ID.to_string_lossy()),
            )
        })
    }
}

/// createInstance: the node made over its params and attached.
pub(super) fn create<E: ImageEffect>(effect: &EffectHandle) -> Outcome {
    let context = effect.context()?;
    let spec = E::describe_in_context(context);
    let params = effect.param_set()?.bind(&spec.params);
    let node = E::create(effect, context, params)?;
    let attached = Arc::new(Attached {
        node: Box::new(node),
        error_shown: AtomicBool::new(false),
    });
    let raw = Arc::into_raw(attached) as *mut c_void;
    effect
        .props()?
        .set_pointer(kOfxPropInstanceData, 0, raw)
        .inspect_err(|_| {
            // SAFETY: `raw` came from Arc::into_raw just above and was not stored.
            drop(unsafe { Arc::from_raw(raw as *const Attached) });
        })
}

/// Takes the instance data back and drops our reference (destroyInstance).
pub(super) fn detach(effect: &EffectHandle) -> Outcome {
    let props = effect.props()?;
    let raw = props.get_pointer(kOfxPropInstanceData, 0)?;
    if raw.is_null() {
        return Ok(());
    }
    props.set_pointer(kOfxPropInstanceData, 0, std::ptr::null_mut())?;
    // SAFETY: a non-null instance pointer is only ever one made by `create`
    // from Arc::into_raw; it is cleared above so this is its only release.
    // Renders still running hold their own clones.
    drop(unsafe { Arc::from_raw(raw as *const Attached) });
    Ok(())
}

/// The instance's node, as a reference-counted handle that stays valid even
/// if the host destroys the instance while this call runs.
pub(super) fn attachment(effect: &EffectHandle) -> Outcome<Arc<Attached>> {
    let raw = effect.props()?.get_pointer(kOfxPropInstanceData, 0)?;
    if raw.is_null() {
        return Err(Failure::Failed(
            "instance has no data: createInstance was not called".into(),
        ));
    }
    let raw = raw as *const Attached;
    // SAFETY: `raw` came from Arc::into_raw in `create` (this layer alone
    // sets the property, and only to such pointers) and the attachment's
    // count is still held (it is cleared before release), so taking one
    // more strong count and materialising it is sound.
    unsafe {
        Arc::increment_strong_count(raw);
        Ok(Arc::from_raw(raw))
    }
}
