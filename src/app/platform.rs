//! What differs between the desktop and the browser, in one place: where saved files go
//! (a dialog's path, or a download), how files are chosen (a blocking dialog, or the
//! browser's picker answering later), and what needs a thread of its own. The rest of the
//! workbench is the same code on both; the render loop's difference is `viewport`'s.

use std::path::{Path, PathBuf};

/// Where a file the user saves goes.
pub enum SaveTarget {
    /// The path chosen in the desktop's dialog.
    Path(PathBuf),
    /// A download of this name (the browser has no file system to write to).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    Download(String),
}

/// Asks where to save a file of kind `what` (`extensions` without dots, the first the
/// default), suggesting `name`. `None` when the user cancels.
pub(crate) fn save_as(what: &str, extensions: &[&str], name: &str) -> Option<SaveTarget> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        let mut dialog = rfd::FileDialog::new().set_file_name(name);
        for ext in extensions {
            dialog = dialog.add_filter(format!("{what} (.{ext})"), &[*ext]);
        }
        dialog.save_file().map(SaveTarget::Path)
    }
    #[cfg(target_arch = "wasm32")]
    {
        let _ = (what, extensions);
        Some(SaveTarget::Download(name.to_string()))
    }
}

impl SaveTarget {
    /// The extension the file will have, lower case.
    pub(crate) fn extension(&self) -> String {
        let name = match self {
            SaveTarget::Path(p) => p.as_path(),
            SaveTarget::Download(n) => Path::new(n),
        };
        name.extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default()
    }

    /// Writes the file: `to_path` writes it at a chosen path, `to_bytes` makes a download's
    /// content. Returns the status line.
    pub(crate) fn write(
        &self,
        to_path: impl FnOnce(&Path) -> crate::Result<()>,
        to_bytes: impl FnOnce() -> crate::Result<Vec<u8>>,
    ) -> String {
        match self {
            SaveTarget::Path(p) => match to_path(p) {
                Ok(()) => format!("wrote {}", p.display()),
                Err(e) => format!("{e:#}"),
            },
            SaveTarget::Download(name) => match to_bytes().and_then(|b| download(name, &b)) {
                Ok(()) => format!("downloaded {name}"),
                Err(e) => format!("{name}: {e:#}"),
            },
        }
    }
}

/// Offers `bytes` as a download named `name` (the browser); unreachable on the desktop.
#[cfg(target_arch = "wasm32")]
fn download(name: &str, bytes: &[u8]) -> crate::Result<()> {
    use wasm_bindgen::JsCast;
    let err = |e: wasm_bindgen::JsValue| crate::Error::from(format!("download failed: {e:?}"));
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let options = web_sys::BlobPropertyBag::new();
    options.set_type("application/octet-stream");
    let blob =
        web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(err)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(err)?;
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("download failed: no document")?;
    let anchor: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(err)?
        .dyn_into()
        .map_err(|_| crate::Error::from("download failed: not an anchor"))?;
    anchor.set_href(&url);
    anchor.set_download(name);
    anchor.click();
    web_sys::Url::revoke_object_url(&url).map_err(err)
}

#[cfg(not(target_arch = "wasm32"))]
fn download(name: &str, _bytes: &[u8]) -> crate::Result<()> {
    Err(format!("{name}: downloads are the browser's").into())
}

/// Asks for a file to open (the desktop's dialog).
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn pick_file(what: &str, extensions: &[&str]) -> Option<PathBuf> {
    rfd::FileDialog::new()
        .add_filter(what, extensions)
        .pick_file()
}

/// Asks for a folder (the desktop's dialog).
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn pick_folder() -> Option<PathBuf> {
    rfd::FileDialog::new().pick_folder()
}

/// A file the browser handed over (dropped, or chosen in its picker): its name and content.
#[derive(Clone)]
pub(crate) struct FileContent {
    pub name: String,
    pub bytes: std::sync::Arc<[u8]>,
}

/// Files the browser's picker has answered with, waiting for the next frame.
#[derive(Clone, Default)]
pub(crate) struct FileInbox(std::sync::Arc<std::sync::Mutex<Vec<FileContent>>>);

impl FileInbox {
    /// The files that arrived since the last call.
    pub(crate) fn take(&self) -> Vec<FileContent> {
        std::mem::take(&mut *self.0.lock().unwrap_or_else(|e| e.into_inner()))
    }

    /// Opens the browser's file picker; the chosen files arrive in this inbox together (and
    /// `wake` is called) once the user has chosen.
    #[cfg(target_arch = "wasm32")]
    pub fn pick(&self, wake: Wake, what: &str, extensions: &[&str]) {
        let dialog = rfd::AsyncFileDialog::new().add_filter(what, extensions);
        let inbox = self.0.clone();
        wasm_bindgen_futures::spawn_local(async move {
            let Some(handles) = dialog.pick_files().await else {
                return;
            };
            let mut files = Vec::new();
            for h in handles {
                files.push(FileContent {
                    name: h.file_name(),
                    bytes: h.read().await.into(),
                });
            }
            inbox
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .extend(files);
            wake();
        });
    }

    /// Reads the files of one drop on the page; they arrive in this inbox together (so that
    /// an OBJ finds its MTL), and `wake` is called.
    #[cfg(target_arch = "wasm32")]
    pub(crate) fn read_dropped(&self, dropped: Vec<egui::DroppedFileHandle>, wake: Wake) {
        let inbox = self.0.clone();
        wasm_bindgen_futures::spawn_local(async move {
            let mut files = Vec::new();
            for f in &dropped {
                let name = f.path().display().to_string();
                match f.bytes_async().await {
                    Ok(bytes) => files.push(FileContent {
                        name,
                        bytes: bytes.into(),
                    }),
                    Err(e) => web_sys::console::error_1(&format!("{name}: {e}").into()),
                }
            }
            inbox
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .extend(files);
            wake();
        });
    }
}

/// Wakes the UI.
#[cfg(target_arch = "wasm32")]
pub(crate) type Wake = std::sync::Arc<dyn Fn() + Send + Sync>;

/// Why work that needs a thread of its own (a benchmark, a lesson's export into a folder)
/// cannot run here; `None` where it can.
pub(crate) fn unavailable_here(what: &str) -> Option<String> {
    if cfg!(target_arch = "wasm32") {
        Some(format!(
            "{what}: in the desktop build only (the browser page has one thread and no folders)"
        ))
    } else {
        None
    }
}

/// A line for the browser's console (`penumbra: …`); nothing on the desktop, whose status
/// bar and terminal say the same.
#[cfg(target_arch = "wasm32")]
pub(crate) fn note(line: &str) {
    web_sys::console::info_1(&format!("penumbra: {line}").into());
}
