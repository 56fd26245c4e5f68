//! A small client of the Chrome DevTools protocol, for the browser tests that act on a
//! page as a person would: move and press the mouse (drag to zoom, hover to read a
//! value), click a download link and read the file saved, take a screenshot.
//!
//! Chromium runs headless with `--remote-debugging-port=0` and says on stderr where its
//! WebSocket listens; one page (a target with a flat session) is driven through it.
//! Commands wait for their answer; events are kept for [`Browser::event`]. Exceptions
//! thrown by the page's scripts are collected and fail [`Browser::assert_no_exceptions`].

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio::io::{AsyncBufReadExt, BufReader};
use tokio::net::TcpStream;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::{MaybeTlsStream, WebSocketStream};

/// Longest wait for one answer of the browser.
const ANSWER_WITHIN: Duration = Duration::from_secs(30);

/// Headless Chromium with one page open.
pub struct Browser {
    _child: tokio::process::Child,
    _profile: tempfile::TempDir,
    socket: WebSocketStream<MaybeTlsStream<TcpStream>>,
    session: String,
    next_id: u64,
    events: Vec<Value>,
    exceptions: Vec<String>,
    downloads: tempfile::TempDir,
}

impl std::fmt::Debug for Browser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Browser").field("session", &self.session).finish()
    }
}

impl Browser {
    /// Starts `chromium` with a viewport of `width` × `height` CSS pixels.
    pub async fn launch(chromium: &Path, width: u32, height: u32) -> Browser {
        let profile = tempfile::TempDir::new().unwrap();
        let mut child = tokio::process::Command::new(chromium)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-dev-shm-usage",
                "--no-first-run",
                "--hide-scrollbars",
                "--remote-debugging-port=0",
            ])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg(format!("--window-size={width},{height}"))
            .arg("about:blank")
            .stderr(std::process::Stdio::piped())
            .stdout(std::process::Stdio::null())
            .kill_on_drop(true)
            .spawn()
            .expect("Chromium starts");
        let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
        let endpoint = tokio::time::timeout(ANSWER_WITHIN, async {
            while let Some(line) = lines.next_line().await.unwrap() {
                if let Some(at) = line.find("ws://") {
                    return line[at..].trim().to_owned();
                }
            }
            panic!("Chromium ended without a DevTools endpoint");
        })
        .await
        .expect("Chromium announces its DevTools endpoint within 30 s");
        // Keep reading its log, or Chromium blocks once the pipe is full.
        tokio::spawn(async move { while let Ok(Some(_)) = lines.next_line().await {} });
        let (socket, _) = tokio_tungstenite::connect_async(endpoint.as_str())
            .await
            .expect("the DevTools WebSocket accepts us");
        let mut browser = Browser {
            _child: child,
            _profile: profile,
            socket,
            session: String::new(),
            next_id: 0,
            events: Vec::new(),
            exceptions: Vec::new(),
            downloads: tempfile::TempDir::new().unwrap(),
        };
        let target = browser
            .send(None, "Target.createTarget", json!({"url": "about:blank"}))
            .await["targetId"]
            .clone();
        browser.session = browser
            .send(
                None,
                "Target.attachToTarget",
                json!({"targetId": target, "flatten": true}),
            )
            .await["sessionId"]
            .as_str()
            .unwrap()
            .to_owned();
        let downloads = browser.downloads.path().display().to_string();
        browser
            .send(
                None,
                "Browser.setDownloadBehavior",
                json!({"behavior": "allowAndName", "downloadPath": downloads, "eventsEnabled": true}),
            )
            .await;
        browser.call("Runtime.enable", json!({})).await;
        browser.call("Page.enable", json!({})).await;
        browser
            .call(
                "Emulation.setDeviceMetricsOverride",
                json!({"width": width, "height": height, "deviceScaleFactor": 1, "mobile": false}),
            )
            .await;
        browser
    }

    /// Sends a command (to the page's session, or to the browser with `None`) and returns
    /// its result; an error answer fails the test.
    async fn send(&mut self, session: Option<String>, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        let mut message = json!({"id": id, "method": method, "params": params});
        if let Some(session) = session {
            message["sessionId"] = json!(session);
        }
        self.socket
            .send(Message::text(message.to_string()))
            .await
            .expect("the DevTools WebSocket takes a command");
        let deadline = Instant::now() + ANSWER_WITHIN;
        loop {
            let message = self
                .receive(deadline)
                .await
                .unwrap_or_else(|| panic!("no answer to {method} within {} s", ANSWER_WITHIN.as_secs()));
            if message["id"] == id {
                if let Some(error) = message.get("error") {
                    panic!("{method} failed: {error}");
                }
                return message["result"].clone();
            }
            self.keep(message);
        }
    }

    /// The next message of the browser, or `None` once `deadline` passed.
    async fn receive(&mut self, deadline: Instant) -> Option<Value> {
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let frame = tokio::time::timeout(left, self.socket.next()).await.ok()?;
            match frame.expect("the DevTools WebSocket stays open").unwrap() {
                Message::Text(text) => return Some(serde_json::from_str(&text).unwrap()),
                Message::Close(frame) => panic!("the DevTools WebSocket closed: {frame:?}"),
                _ => {}
            }
        }
    }

    fn keep(&mut self, event: Value) {
        if event["method"] == "Runtime.exceptionThrown" {
            let details = &event["params"]["exceptionDetails"];
            self.exceptions.push(format!(
                "{} {}",
                details["text"], details["exception"]["description"]
            ));
        }
        self.events.push(event);
    }

    /// A command to the page.
    pub async fn call(&mut self, method: &str, params: Value) -> Value {
        let session = self.session.clone();
        self.send(Some(session), method, params).await
    }

    /// Loads `url` and waits for its `load` event.
    pub async fn goto(&mut self, url: &str) {
        self.events.clear();
        self.call("Page.navigate", json!({"url": url})).await;
        self.event("Page.loadEventFired", Duration::from_secs(30)).await;
    }

    /// The value of a JavaScript expression in the page (promises awaited); an exception
    /// fails the test.
    pub async fn eval(&mut self, expression: &str) -> Value {
        let answer = self
            .call(
                "Runtime.evaluate",
                json!({"expression": expression, "returnByValue": true, "awaitPromise": true}),
            )
            .await;
        if let Some(details) = answer.get("exceptionDetails") {
            panic!("{expression} threw: {details}");
        }
        answer["result"]["value"].clone()
    }

    /// Evaluates `expression` every 50 ms until it is truthy; returns that value.
    pub async fn wait_for(&mut self, expression: &str, within: Duration) -> Value {
        let deadline = Instant::now() + within;
        loop {
            let value = self.eval(expression).await;
            let truthy = match &value {
                Value::Null | Value::Bool(false) => false,
                Value::String(text) => !text.is_empty(),
                Value::Number(n) => n.as_f64() != Some(0.0),
                _ => true,
            };
            if truthy {
                return value;
            }
            assert!(
                Instant::now() < deadline,
                "`{expression}` still {value} after {} s",
                within.as_secs_f64()
            );
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }

    /// The first event called `method` since the last page load (waiting for it).
    pub async fn event(&mut self, method: &str, within: Duration) -> Value {
        let deadline = Instant::now() + within;
        loop {
            if let Some(event) = self.events.iter().find(|e| e["method"] == method) {
                return event["params"].clone();
            }
            let message = self
                .receive(deadline)
                .await
                .unwrap_or_else(|| panic!("no {method} within {} s", within.as_secs_f64()));
            self.keep(message);
        }
    }

    /// A mouse event at (x, y) CSS pixels of the viewport: `mouseMoved`, `mousePressed`,
    /// `mouseReleased`; `pressed`: whether the left button is down.
    pub async fn mouse(&mut self, kind: &str, x: f64, y: f64, pressed: bool) {
        let mut params = json!({"type": kind, "x": x, "y": y, "buttons": if pressed { 1 } else { 0 }});
        if kind != "mouseMoved" {
            params["button"] = json!("left");
            params["clickCount"] = json!(1);
        } else if pressed {
            params["button"] = json!("left");
        }
        self.call("Input.dispatchMouseEvent", params).await;
    }

    /// Presses the left button at `from`, moves to `to` in ten steps, releases it there.
    pub async fn drag(&mut self, from: (f64, f64), to: (f64, f64)) {
        self.mouse("mouseMoved", from.0, from.1, false).await;
        self.mouse("mousePressed", from.0, from.1, true).await;
        for step in 1..=10 {
            let t = f64::from(step) / 10.0;
            let (x, y) = (from.0 + t * (to.0 - from.0), from.1 + t * (to.1 - from.1));
            self.mouse("mouseMoved", x, y, true).await;
        }
        self.mouse("mouseReleased", to.0, to.1, false).await;
    }

    /// Clicks the element `selector` (scrolled into view first) at its centre.
    pub async fn click(&mut self, selector: &str) {
        let centre = self
            .eval(&format!(
                "(() => {{ const e = document.querySelector({selector:?}); e.scrollIntoView({{block: 'center'}}); \
                 const r = e.getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]; }})()"
            ))
            .await;
        let (x, y) = (centre[0].as_f64().unwrap(), centre[1].as_f64().unwrap());
        self.mouse("mouseMoved", x, y, false).await;
        self.mouse("mousePressed", x, y, true).await;
        self.mouse("mouseReleased", x, y, false).await;
    }

    /// After a click on a download link: its suggested file name and its bytes.
    pub async fn downloaded(&mut self) -> (String, Vec<u8>) {
        let within = Duration::from_secs(20);
        let begun = self.event("Browser.downloadWillBegin", within).await;
        let guid = begun["guid"].as_str().unwrap().to_owned();
        let deadline = Instant::now() + within;
        loop {
            let done = self.events.iter().any(|e| {
                e["method"] == "Browser.downloadProgress"
                    && e["params"]["guid"] == guid.as_str()
                    && e["params"]["state"] == "completed"
            });
            if done {
                break;
            }
            let message = self.receive(deadline).await.expect("the download completes");
            self.keep(message);
        }
        self.events.retain(|e| e["params"]["guid"] != guid.as_str());
        let path: PathBuf = self.downloads.path().join(&guid);
        let name = begun["suggestedFilename"].as_str().unwrap().to_owned();
        (name, std::fs::read(path).unwrap())
    }

    /// Saves a PNG of the viewport as `path`.
    pub async fn screenshot(&mut self, path: &Path) {
        let shot = self
            .call("Page.captureScreenshot", json!({"format": "png"}))
            .await;
        std::fs::write(path, base64_decode(shot["data"].as_str().unwrap())).unwrap();
    }

    /// Fails the test with the exceptions the page's scripts threw, if any.
    pub fn assert_no_exceptions(&self) {
        assert!(
            self.exceptions.is_empty(),
            "script errors: {:#?}",
            self.exceptions
        );
    }
}

/// Standard base64 (RFC 4648, padded), as DevTools sends binary data.
pub(crate) fn base64_decode(text: &str) -> Vec<u8> {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut bytes = Vec::with_capacity(text.len() * 3 / 4);
    let (mut buffer, mut bits) = (0u32, 0u32);
    for c in text.bytes().filter(|&c| c != b'=') {
        let value = ALPHABET.iter().position(|&a| a == c).expect("a base64 character") as u32;
        buffer = (buffer << 6) | value;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            bytes.push((buffer >> bits) as u8);
            buffer &= (1 << bits) - 1;
        }
    }
    bytes
}

#[test]
fn base64_decodes_the_rfc_4648_vectors() {
    for (text, plain) in [
        ("", ""),
        ("Zg==", "f"),
        ("Zm8=", "fo"),
        ("Zm9v", "foo"),
        ("Zm9vYg==", "foob"),
        ("Zm9vYmE=", "fooba"),
        ("Zm9vYmFy", "foobar"),
    ] {
        assert_eq!(base64_decode(text), plain.as_bytes(), "{text}");
    }
}
