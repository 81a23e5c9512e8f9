//! Decoding a snapshot body for both rapier backends: postcard into the backend's state,
//! then the backend's cross-reference checks, with a panic anywhere in between (rapier's
//! containers assume their own invariants, which edited bytes can break) turned into a
//! refusal. Nothing of the plane is touched before this returns.

use shm_layout::CommandError;

/// `body` decoded into `T` and passed through `check`; an error or a panic is the refusal
/// `refused(why)`.
pub fn decode<T: serde::de::DeserializeOwned>(
    body: &[u8],
    refused: fn(String) -> CommandError,
    check: fn(&T) -> Result<(), CommandError>,
) -> Result<T, CommandError> {
    let decoded = std::panic::catch_unwind(|| {
        let state: T = postcard::from_bytes(body)
            .map_err(|e| refused(format!("its state does not decode ({e})")))?;
        check(&state)?;
        Ok(state)
    });
    match decoded {
        Ok(result) => result,
        Err(_) => Err(refused(
            "its engine state does not hold together (edited bytes?)".to_string(),
        )),
    }
}
