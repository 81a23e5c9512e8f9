//! The HTTP side: the page and its script (embedded in the binary, three.js included, so
//! nothing is fetched from elsewhere at run time) and the JSON API the page polls. Every
//! answer that needs the daemon is a job for the sampler thread.

use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};

use axum::extract::{Path, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde_json::{json, Value};
use tokio::sync::oneshot;

use crate::replay::ReplayRequest;
use crate::sampler::{Action, Job, Overview};

const INDEX_HTML: &str = include_str!("../static/index.html");
const APP_JS: &str = include_str!("../static/app.js");
/// three.js r187 (MIT, `static/THREE-LICENSE`) with its OrbitControls, bundled and minified
/// from the npm package `three@0.187.0` (see `static/README.md`).
const THREE_JS: &str = include_str!("../static/three.module.min.js");

/// What every handler shares.
#[derive(Clone)]
pub struct AppState {
    /// The sampler's published overview.
    pub overview: Arc<Mutex<Overview>>,
    /// Jobs for the sampler thread.
    pub jobs: Sender<Job>,
    /// Whether pause / step / resume are allowed.
    pub allow_control: bool,
    /// The daemon's domain.
    pub domain: String,
}

/// The router of the viewer.
pub fn router(state: AppState) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/static/app.js", get(app_js))
        .route("/static/three.module.min.js", get(three_js))
        .route("/api/info", get(info))
        .route("/api/planes", get(planes))
        .route("/api/plane/{id}", get(snapshot))
        .route("/api/plane/{id}/history", get(history))
        .route("/api/plane/{id}/body/{slot}", get(body))
        .route("/api/plane/{id}/{action}", post(control))
        .route("/api/plane/{id}/snapshot", get(download))
        .route("/api/replay", get(replay_status).post(replay_action))
        .with_state(state)
}

fn javascript(body: &'static str) -> Response {
    (
        [
            (header::CONTENT_TYPE, "text/javascript; charset=utf-8"),
            (header::CACHE_CONTROL, "max-age=3600"),
        ],
        body,
    )
        .into_response()
}

async fn index() -> Response {
    (
        [(header::CONTENT_TYPE, "text/html; charset=utf-8")],
        INDEX_HTML,
    )
        .into_response()
}

async fn app_js() -> Response {
    javascript(APP_JS)
}

async fn three_js() -> Response {
    javascript(THREE_JS)
}

fn error(status: StatusCode, message: impl Into<String>) -> Response {
    (status, Json(json!({ "error": message.into() }))).into_response()
}

async fn info(State(s): State<AppState>) -> Response {
    let o = s.overview.lock().expect("overview lock");
    Json(json!({
        "domain": s.domain,
        "allow_control": s.allow_control,
        "connected": o.connected,
        "error": o.error,
        "daemon_pid": o.daemon_pid,
        "version": env!("CARGO_PKG_VERSION"),
        "replay": o.replay_file.as_ref().map(|file| json!({
            "file": file,
            "plane": o.replay_plane,
        })),
    }))
    .into_response()
}

async fn planes(State(s): State<AppState>) -> Response {
    let o = s.overview.lock().expect("overview lock");
    Json(json!(o.planes)).into_response()
}

async fn history(State(s): State<AppState>, Path(id): Path<u32>) -> Response {
    let o = s.overview.lock().expect("overview lock");
    match o.histories.get(&id) {
        Some(h) => Json(json!(h)).into_response(),
        None => error(StatusCode::NOT_FOUND, format!("no plane {id} is known")),
    }
}

/// Sends a job to the sampler and waits for its answer.
async fn ask(
    s: &AppState,
    failed: StatusCode,
    job: impl FnOnce(oneshot::Sender<Result<Value, String>>) -> Job,
) -> Response {
    let (tx, rx) = oneshot::channel();
    if s.jobs.send(job(tx)).is_err() {
        return error(StatusCode::SERVICE_UNAVAILABLE, "the sampler has stopped");
    }
    match rx.await {
        Ok(Ok(v)) => Json(v).into_response(),
        Ok(Err(message)) => error(failed, message),
        Err(_) => error(StatusCode::SERVICE_UNAVAILABLE, "the sampler has stopped"),
    }
}

async fn snapshot(State(s): State<AppState>, Path(plane): Path<u32>) -> Response {
    ask(&s, StatusCode::NOT_FOUND, |reply| Job::Snapshot {
        plane,
        reply,
    })
    .await
}

async fn body(State(s): State<AppState>, Path((plane, slot)): Path<(u32, u32)>) -> Response {
    ask(&s, StatusCode::NOT_FOUND, |reply| Job::Body {
        plane,
        slot,
        reply,
    })
    .await
}

async fn control(
    State(s): State<AppState>,
    Path((plane, action)): Path<(u32, String)>,
) -> Response {
    let Some(action) = Action::parse(&action) else {
        return error(
            StatusCode::NOT_FOUND,
            format!("unknown control {action:?} (pause, step or resume)"),
        );
    };
    if !s.allow_control {
        return error(
            StatusCode::FORBIDDEN,
            "controls are off: the viewer is read-only unless started with --allow-control",
        );
    }
    // The daemon refused (not the owner, not a manual plane, ...): the request conflicts
    // with the plane's state, it did not fail to find it.
    ask(&s, StatusCode::CONFLICT, |reply| Job::Control {
        plane,
        action,
        reply,
    })
    .await
}

/// "Download snapshot": the plane's whole state as a `.physnap` file (what
/// `snapshot:Save(path)` writes; `PhysicsService.LoadSnapshot`, `FromSnapshot` and
/// `physics-lua --snapshot FILE` take it). A read: no `--allow-control` needed.
async fn download(State(s): State<AppState>, Path(plane): Path<u32>) -> Response {
    let (tx, rx) = oneshot::channel();
    if s.jobs.send(Job::Download { plane, reply: tx }).is_err() {
        return error(StatusCode::SERVICE_UNAVAILABLE, "the sampler has stopped");
    }
    match rx.await {
        Ok(Ok((tick, bytes))) => (
            [
                (header::CONTENT_TYPE, "application/octet-stream".to_string()),
                (
                    header::CONTENT_DISPOSITION,
                    format!("attachment; filename=\"plane-{plane}-tick-{tick}.physnap\""),
                ),
            ],
            bytes,
        )
            .into_response(),
        Ok(Err(message)) => error(StatusCode::NOT_FOUND, message),
        Err(_) => error(StatusCode::SERVICE_UNAVAILABLE, "the sampler has stopped"),
    }
}

/// Sends a timeline job to the sampler and waits for its answer.
async fn ask_replay(s: &AppState, request: Option<ReplayRequest>) -> Response {
    let (tx, rx) = oneshot::channel();
    if s.jobs.send(Job::Replay { request, reply: tx }).is_err() {
        return error(StatusCode::SERVICE_UNAVAILABLE, "the sampler has stopped");
    }
    match rx.await {
        Ok(Ok(v)) => Json(v).into_response(),
        Ok(Err((status, message))) => error(
            StatusCode::from_u16(status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR),
            message,
        ),
        Err(_) => error(StatusCode::SERVICE_UNAVAILABLE, "the sampler has stopped"),
    }
}

/// `GET /api/replay`: the timeline of `--replay FILE` (first and last tick, the current
/// one, playing, speed, a divergence's message).
async fn replay_status(State(s): State<AppState>) -> Response {
    ask_replay(&s, None).await
}

/// `POST /api/replay` with `{"action": "play"|"pause"|"step"|"seek"|"speed", "tick"?,
/// "speed"?}`. It drives the viewer's own replay plane only, so it needs no
/// `--allow-control`.
async fn replay_action(State(s): State<AppState>, body: axum::body::Bytes) -> Response {
    match ReplayRequest::parse(&body) {
        Ok(request) => ask_replay(&s, Some(request)).await,
        Err(message) => error(StatusCode::BAD_REQUEST, message),
    }
}
