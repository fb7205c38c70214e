//! Headless Chromium for the animation pages' tests: run it on a page, read the serialised
//! DOM back, check the page fits the window.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The window the pages are checked in (CSS pixels).
pub const WINDOW: (f64, f64) = (1000.0, 700.0);

/// Chromium at `$CHROMIUM` or /usr/bin/chromium, if installed.
pub fn chromium() -> Option<PathBuf> {
    let p = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    p.exists().then_some(p)
}

/// Runs Chromium headless with a fresh profile in a window of `size`; returns stdout (read
/// while Chromium runs: a DOM larger than the pipe's buffer would otherwise block it).
pub fn chrome(bin: &Path, profile: &Path, size: (f64, f64), extra: &[String]) -> String {
    let mut child = Command::new(bin)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
        ])
        .arg(format!("--window-size={},{}", size.0, size.1))
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromium starts");
    let mut stdout = child.stdout.take().expect("chromium's stdout");
    let reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        std::io::Read::read_to_end(&mut stdout, &mut buf).map(|_| buf)
    });
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait on chromium").is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish within 120 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = reader
        .join()
        .expect("the reader thread")
        .expect("chromium's output");
    String::from_utf8_lossy(&out).into_owned()
}

/// The DOM of the page at `url` as laid out in a 1000 x 700 viewport. Headless Chromium's
/// `--dump-dom` gives the page less than the window (143 px less height in Chromium 156, as if
/// for a toolbar; `--screenshot` gives it all), so the window is grown by what the page
/// reported missing and the page loaded again.
pub fn dom_at_1000x700(bin: &Path, dir: &Path, url: &str) -> String {
    let mut size = WINDOW;
    for attempt in 0..2 {
        let profile = dir.join(format!("profile-dom-{attempt}"));
        let dom = chrome(bin, &profile, size, &["--dump-dom".into(), url.to_string()]);
        let html = &elements(&dom, "html")[0];
        let inner = (html.num("data-inner-width"), html.num("data-inner-height"));
        if inner == WINDOW {
            return dom;
        }
        size = (size.0 + WINDOW.0 - inner.0, size.1 + WINDOW.1 - inner.1);
    }
    panic!("no window size gives the page a 1000 x 700 viewport");
}

/// One element of serialised HTML: its attributes and the text up to its closing tag.
pub struct Element {
    /// The attributes.
    pub attrs: HashMap<String, String>,
    /// The text up to the closing tag.
    pub text: String,
}

impl Element {
    /// An attribute.
    pub fn get(&self, k: &str) -> Option<&str> {
        self.attrs.get(k).map(String::as_str)
    }
    /// An attribute as a number (panics when missing or not a number).
    pub fn num(&self, k: &str) -> f64 {
        let v = self
            .get(k)
            .unwrap_or_else(|| panic!("attribute {k} missing in {:?}", self.attrs));
        v.parse()
            .unwrap_or_else(|_| panic!("attribute {k} = {v:?} is not a number"))
    }
    /// Whether the element has the class.
    pub fn has_class(&self, c: &str) -> bool {
        self.get("class")
            .is_some_and(|s| s.split_whitespace().any(|w| w == c))
    }
}

/// Every `<tag ...>` element of serialised HTML.
pub fn elements(html: &str, tag: &str) -> Vec<Element> {
    let open = format!("<{tag} ");
    let close = format!("</{tag}>");
    let mut v = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find(&open) {
        rest = &rest[i + open.len()..];
        let end = rest.find('>').expect("tag closes");
        let mut attrs = HashMap::new();
        let mut s = &rest[..end];
        while let Some(eq) = s.find("=\"") {
            let name = s[..eq].trim().to_string();
            let after = &s[eq + 2..];
            let close = after.find('"').expect("attribute closes");
            attrs.insert(name, after[..close].to_string());
            s = &after[close + 1..];
        }
        let body = &rest[end + 1..];
        let text = body.find(&close).map_or("", |k| &body[..k]).to_string();
        v.push(Element { attrs, text });
    }
    v
}

/// The element with the id.
pub fn by_id<'a>(els: &'a [Element], id: &str) -> &'a Element {
    els.iter()
        .find(|e| e.get("id") == Some(id))
        .unwrap_or_else(|| panic!("no element #{id}"))
}

/// Width and height of a PNG (its IHDR chunk).
pub fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.starts_with(b"\x89PNG"), "not a PNG");
    let be = |k: usize| u32::from_be_bytes([bytes[k], bytes[k + 1], bytes[k + 2], bytes[k + 3]]);
    (be(16), be(20))
}

/// The page fits the 1000 x 700 window: no scrollbar either way.
pub fn check_fits_the_window(dom: &str) {
    let html = &elements(dom, "html")[0];
    let (iw, ih) = (html.num("data-inner-width"), html.num("data-inner-height"));
    assert_eq!(
        (iw, ih),
        WINDOW,
        "the page was laid out in a 1000 x 700 window"
    );
    let (sw, sh) = (
        html.num("data-scroll-width"),
        html.num("data-scroll-height"),
    );
    assert!(
        sw <= iw && sh <= ih,
        "the page needs a scrollbar: content {sw} x {sh} in a {iw} x {ih} window"
    );
}
