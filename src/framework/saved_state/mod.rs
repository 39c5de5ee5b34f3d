//! A model's internal state in an FMU state, all of it on the model's side: one codec for
//! every model (a [`StateLayout`] version, then postcard), the one check of each model's
//! restored state ([`SavedState`], [`Model::check_state`](super::model::Model::check_state)),
//! the checks every number in it can get ([`all_finite`], [`all_positive`], from `walk`),
//! and the state methods of a sampled model written once (`sampled_state_methods!`).
//! The FMI side (the snapshot around it, handles, ownership) is `crate::fmi::fmu_state`.

pub mod bytes;
mod walk;

pub use walk::{all_finite, all_positive};

use super::model::Environment;

/// The three state methods of a sampled model whose internal state is
/// `self.state: Option<State>` (`None` before initialization), saved with layout `$layout`
/// and checked by its [`SavedState`] in the model's `self.environment`, and its step check
/// (the sample clock's): the same in every such model, written once.
macro_rules! sampled_state_methods {
    ($state:ty, $layout:expr) => {
        fn save_state(&self) -> Result<Vec<u8>, String> {
            $crate::framework::saved_state::encode_state($layout, &self.state)
        }

        fn check_state(&self, bytes: &[u8], time: f64) -> $crate::framework::model::ModelResult {
            $crate::framework::saved_state::decode_checked::<$state>(
                $layout,
                bytes,
                time,
                &self.environment,
            )
            .map(drop)
        }

        fn restore_state(
            &mut self,
            bytes: &[u8],
            time: f64,
        ) -> $crate::framework::model::ModelResult {
            self.state = $crate::framework::saved_state::decode_checked(
                $layout,
                bytes,
                time,
                &self.environment,
            )?;
            Ok(())
        }

        // Not a state method, but every sampled model has its clock in `self.state`.
        fn check_step(&self, time: f64, step: f64) -> $crate::framework::model::ModelResult {
            match &self.state {
                Some(state) => state.clock.check_step(time + step),
                None => Ok(()),
            }
        }
    };
}
pub(crate) use sampled_state_methods;

/// The version of one model's internal state layout. Bump `version` whenever the saved
/// state of that model changes shape or meaning (a field added, a type changed, a unit
/// changed): states saved with another layout are then refused with a message instead of
/// being misread. The interface GUID does not cover the internal state, so this is the
/// only guard.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateLayout {
    /// The model's identifier, for messages.
    pub model: &'static str,
    pub version: u16,
}

/// A sampled model's internal state, which has one check once restored: like the
/// parameters it was built from, at the instance time `time` saved with it, in the
/// `environment` of the model it is restored into (what a restore that rebuilds part of
/// the state, a plan, may need); the error names the cause.
pub trait SavedState: serde::de::DeserializeOwned {
    fn validate(&self, time: f64, environment: &Environment) -> Result<(), String>;
}

/// How a sampled model's state comes back from its bytes. A [`SavedState`] is read as it
/// is and then checked; a state that rebuilds part of itself on restore (the five-axis
/// interpolator's plan, through the environment's planner) is read in a form of the same
/// layout, `Saved`, and made from it, checked on the way.
pub trait RestoredState: Sized {
    /// What the bytes are read as.
    type Saved: serde::de::DeserializeOwned;
    /// The state made from what was read, at the instance time `time`, in the
    /// `environment` of the model it is restored into; the error names the cause.
    fn restore(saved: Self::Saved, time: f64, environment: &Environment) -> Result<Self, String>;
}

impl<S: SavedState> RestoredState for S {
    type Saved = S;

    fn restore(state: S, time: f64, environment: &Environment) -> Result<S, String> {
        state.validate(time, environment)?;
        Ok(state)
    }
}

/// [`decode_state`] of a sampled model's optional state (`None` before initialization),
/// then its [`RestoredState::restore`].
pub fn decode_checked<S: RestoredState>(
    layout: StateLayout,
    bytes: &[u8],
    time: f64,
    environment: &Environment,
) -> Result<Option<S>, String> {
    let saved: Option<S::Saved> = decode_state(layout, bytes)?;
    saved
        .map(|saved| S::restore(saved, time, environment))
        .transpose()
}

/// Serialises a model's internal state with the same codec for every model: the layout
/// version (u16, little endian), then the state in postcard.
pub fn encode_state<T: serde::Serialize>(
    layout: StateLayout,
    state: &T,
) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::with_capacity(256);
    bytes.extend_from_slice(&layout.version.to_le_bytes());
    postcard::to_extend(state, bytes).map_err(|e| format!("cannot encode the model state: {e}"))
}

/// The inverse of [`encode_state`]: refuses another layout version, truncated bytes and
/// trailing bytes. The caller still validates the values.
pub fn decode_state<T: serde::de::DeserializeOwned>(
    layout: StateLayout,
    bytes: &[u8],
) -> Result<T, String> {
    let Some((version, body)) = bytes.split_first_chunk::<2>() else {
        return Err(format!(
            "the {} state is truncated (no layout version)",
            layout.model
        ));
    };
    let version = u16::from_le_bytes(*version);
    if version != layout.version {
        let age = if version < layout.version {
            "an older"
        } else {
            "a newer"
        };
        return Err(format!(
            "the {} state has internal layout version {version}, this build reads layout \
             version {} only: it was saved by {age} build of contour-fmu and cannot be restored",
            layout.model, layout.version
        ));
    }
    let (state, rest) = postcard::take_from_bytes(body)
        .map_err(|e| format!("cannot decode the {} state: {e}", layout.model))?;
    if !rest.is_empty() {
        return Err(format!(
            "cannot decode the {} state: {} trailing bytes",
            layout.model,
            rest.len()
        ));
    }
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_states_carry_their_layout_version() {
        let layout = StateLayout {
            model: "Demo",
            version: 3,
        };
        let bytes = encode_state(layout, &(1.5f64, 7u32)).unwrap();
        assert_eq!(&bytes[..2], &[3, 0]);
        assert_eq!(decode_state::<(f64, u32)>(layout, &bytes), Ok((1.5, 7)));
        let older = StateLayout {
            version: 4,
            ..layout
        };
        let message = decode_state::<(f64, u32)>(older, &bytes).unwrap_err();
        assert_eq!(
            message,
            "the Demo state has internal layout version 3, this build reads layout version 4 \
             only: it was saved by an older build of contour-fmu and cannot be restored"
        );
        let newer = StateLayout {
            version: 2,
            ..layout
        };
        assert!(decode_state::<(f64, u32)>(newer, &bytes)
            .unwrap_err()
            .contains("a newer build"));
        assert!(decode_state::<(f64, u32)>(layout, &bytes[..1])
            .unwrap_err()
            .contains("truncated"));
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode_state::<(f64, u32)>(layout, &longer)
            .unwrap_err()
            .contains("1 trailing bytes"));
    }
}
