//! The workbench in a browser page (docs/web.md): eframe's web runner on the page's canvas,
//! the same `WorkbenchApp` as the desktop's window. The page's address may choose what opens:
//! `?scene=fig4&preset=teach&method=ratio`.

use super::WorkbenchApp;
use super::layout::Preset;
use wasm_bindgen::JsCast;

/// Starts the workbench on the canvas `#penumbra` of the page (the page's `main`).
pub fn start() {
    // A panic is reported on the page's console (where the browser test looks for one),
    // not lost in the wasm trap that follows it.
    std::panic::set_hook(Box::new(|info| {
        web_sys::console::error_1(&format!("penumbra panicked: {info}").into());
    }));
    let Some(document) = web_sys::window().and_then(|w| w.document()) else {
        return;
    };
    let Some(canvas) = document
        .get_element_by_id("penumbra")
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
    else {
        web_sys::console::error_1(&"the page has no <canvas id=\"penumbra\">".into());
        return;
    };
    let query = page_query();
    wasm_bindgen_futures::spawn_local(async move {
        let started = eframe::WebRunner::new()
            .start(
                canvas,
                eframe::WebOptions {
                    renderer: eframe::Renderer::Glow,
                    ..Default::default()
                },
                Box::new(move |cc| {
                    let mut app = WorkbenchApp::from_creation_context(cc, Default::default());
                    // A scene remembered from a dropped file cannot be read again (the page
                    // keeps no files): start on the default scene instead of an error.
                    let embedded = crate::scene::scene_file::embedded_scene_names();
                    if !embedded.contains(&app.settings.scene.as_str()) {
                        app.load_scene("default");
                    }
                    for (key, value) in &query {
                        match key.as_str() {
                            "scene" => app.load_scene(value),
                            "method" => match crate::render::RenderMethod::ALL
                                .into_iter()
                                .find(|m| m.name() == value)
                            {
                                Some(m) => app.settings.method = m,
                                None => {
                                    web_sys::console::warn_1(&format!("no method '{value}'").into())
                                }
                            },
                            "preset" => match Preset::from_name(value) {
                                Some(p) => app.set_preset(p),
                                None => {
                                    web_sys::console::warn_1(&format!("no preset '{value}'").into())
                                }
                            },
                            _ => {}
                        }
                    }
                    Ok(Box::new(app))
                }),
            )
            .await;
        match started {
            Ok(()) => {
                if let Some(loading) = document.get_element_by_id("loading") {
                    loading.remove();
                }
            }
            Err(e) => {
                web_sys::console::error_1(&format!("the workbench did not start: {e:?}").into())
            }
        }
    });
}

/// The page address's query as (key, value) pairs, `+` and `%XX` decoded.
fn page_query() -> Vec<(String, String)> {
    let search = web_sys::window()
        .and_then(|w| w.location().search().ok())
        .unwrap_or_default();
    search
        .trim_start_matches('?')
        .split('&')
        .filter(|kv| !kv.is_empty())
        .map(|kv| {
            let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
            (decode(k), decode(v))
        })
        .collect()
}

fn decode(s: &str) -> String {
    js_sys::decode_uri_component(&s.replace('+', " "))
        .map(String::from)
        .unwrap_or_else(|_| s.to_string())
}
