//! The panel's web server (`tiny_http`, a thread a request): the page's
//! files and dependencies (`vendor/…`), `bridge.json` (the head bridged
//! to, if any), `GET /events` (the head's bytes as server-sent events of
//! hex digits; `gone` with the reason when it goes away), `POST /send`.

use std::{
    io::Write,
    net::SocketAddr,
    path::{Path, PathBuf},
    sync::{Arc, mpsc},
    thread,
};

use anyhow::{Context, Result, anyhow};
use tiny_http::{Header, Method, Request, Response};

use super::bridge::{Bridge, Note};
use super::{VENDOR, content_type};

/// `bridge.json` of a page served without a bridge (and of an exported
/// copy): the page offers Web Serial.
pub const NO_BRIDGE: &str = r#"{"bridge":null}"#;

/// The running server; dropping it stops it (and its bridge).
pub struct Server {
    http: Arc<tiny_http::Server>,
    accepting: Option<thread::JoinHandle<()>>,
    pub address: SocketAddr,
}

impl Server {
    /// Serves `root`'s `panel/` on `listen`, bridged to `bridge`; a head
    /// that goes away is told on `stopped` too (the command then ends,
    /// saying so).
    pub fn start(
        root: &Path,
        listen: SocketAddr,
        bridge: Option<Bridge>,
        stopped: mpsc::Sender<String>,
    ) -> Result<Self> {
        let http =
            tiny_http::Server::http(listen).map_err(|e| anyhow!("listening on {listen}: {e}"))?;
        let http = Arc::new(http);
        let address = http.server_addr().to_ip().context("a TCP address")?;
        let bridge = bridge.map(Arc::new);
        if let Some(bridge) = &bridge {
            let notes = bridge.hub.join();
            thread::spawn(move || {
                if let Some(why) = notes.iter().find_map(|n| match n {
                    Note::Gone(why) => Some(why),
                    Note::Bytes(_) => None,
                }) {
                    let _ = stopped.send(format!("the head went away ({why})"));
                }
            });
        }
        let panel = root.join("panel");
        let serving = Arc::clone(&http);
        let accepting = thread::spawn(move || {
            for request in serving.incoming_requests() {
                let (panel, bridge) = (panel.clone(), bridge.clone());
                thread::spawn(move || serve(request, &panel, bridge));
            }
        });
        Ok(Self {
            http,
            accepting: Some(accepting),
            address,
        })
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        // The accepting thread holds the bridge; a request holds it while
        // it is answered, an event stream not at all.
        self.http.unblock();
        if let Some(accepting) = self.accepting.take() {
            let _ = accepting.join();
        }
    }
}

fn serve(mut request: Request, panel: &Path, bridge: Option<Arc<Bridge>>) {
    let url = request.url();
    let path = url.split(['?', '#']).next().unwrap_or(url).to_owned();
    let text = |status, body: &str| Response::from_string(body).with_status_code(status);
    let answer = match (request.method(), path.as_str(), bridge) {
        (Method::Get, "/events", Some(bridge)) => {
            let notes = bridge.hub.join();
            drop(bridge);
            let _ = events(request.into_writer(), &notes);
            return;
        }
        (Method::Post, "/send", Some(bridge)) => {
            let mut bytes = Vec::new();
            let sent = request.as_reader().read_to_end(&mut bytes);
            match sent
                .map_err(anyhow::Error::from)
                .and_then(|_| bridge.write(&bytes))
            {
                Ok(()) => text(200, "sent"),
                Err(e) => text(503, &format!("not sent: {e:#}")),
            }
        }
        (Method::Get, "/bridge.json", bridge) => {
            let body = bridge.map_or_else(
                || NO_BRIDGE.to_owned(),
                |b| serde_json::json!({"bridge": b.kind, "name": b.name}).to_string(),
            );
            file(&body.into_bytes(), "application/json")
        }
        (Method::Get, path, _) => match page_file(panel, path) {
            Some((bytes, kind)) => file(&bytes, kind),
            None => text(404, "not found"),
        },
        _ => text(405, "the page is static: GET it"),
    };
    let _ = request.respond(answer);
}

fn file(bytes: &[u8], kind: &str) -> Response<std::io::Cursor<Vec<u8>>> {
    let header = |name: &str, value: &str| Header::from_bytes(name, value).expect("a valid header");
    let response = Response::from_data(bytes.to_vec()).with_header(header("Content-Type", kind));
    response.with_header(header("Cache-Control", "no-store"))
}

/// The file `path` names: the page's own (in `panel/`), or a dependency's.
fn page_file(panel: &Path, path: &str) -> Option<(Vec<u8>, &'static str)> {
    let file: PathBuf = match path.trim_start_matches('/') {
        "" => panel.join("index.html"),
        vendor if vendor.starts_with("vendor/") => {
            let url = vendor.trim_start_matches("vendor/");
            let (_, file) = VENDOR.iter().find(|(u, _)| *u == url)?;
            panel.join("node_modules").join(file)
        }
        name if !name.contains('/') && !name.starts_with('.') => panel.join(name),
        _ => return None,
    };
    Some((std::fs::read(&file).ok()?, content_type(&file)?))
}

/// The event stream: the head's bytes, until it goes away or the page does.
fn events(mut out: Box<dyn Write + Send>, notes: &mpsc::Receiver<Note>) -> std::io::Result<()> {
    out.write_all(
        b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n\
          Connection: close\r\n\r\n",
    )?;
    out.flush()?;
    for note in notes {
        match note {
            Note::Bytes(bytes) => {
                write!(out, "data: {}\n\n", crate::sim::node::hex_string(&bytes))?;
            }
            Note::Gone(why) => {
                write!(out, "event: gone\ndata: {why}\n\n")?;
                return out.flush();
            }
        }
        out.flush()?;
    }
    Ok(())
}
