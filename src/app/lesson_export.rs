//! A stepped lesson for slides: one picture of the sphere (or the projected plane, at a set
//! difference) per stage of the picked point, written as numbered PNG frames, an animated GIF
//! and a text file with each frame's lesson (`docs/workbench.md`, "Exporting a lesson").
//!
//! The capture is a small state machine the app advances once per frame: set the step, let the
//! tiles lay it out for a few frames, ask egui for a screenshot of the subject's tile, go on.
//! The writing is a plain function of the frames, so that it can be tested without a window.

use super::lesson::Lesson;
use crate::Result;
use crate::error::InFile;
use egui::ColorImage;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// One frame of the lesson: what the stepper showed and the picture of it.
#[derive(Clone, Debug)]
pub(crate) struct LessonFrame {
    /// The stepper's label of the stage ("light quad: clipped to the horizon", …).
    pub label: String,
    /// The lesson text of the stage with the point's numbers (`None` if the page lacks it).
    pub lesson: Option<Lesson>,
    pub image: ColorImage,
}

/// What [`write_lesson`] wrote.
#[derive(Clone, Debug)]
pub(crate) struct LessonFiles {
    pub frames: Vec<PathBuf>,
    pub gif: PathBuf,
    pub text: PathBuf,
}

/// Writes `frame_000.png`, … , `lesson.gif` (each frame shown `seconds`, looping) and
/// `lesson.md` (per frame: the stage, its explanation, equation and numbers) into `dir`.
/// Frames of a different size than the first are padded or cropped to it (a GIF has one size).
pub(crate) fn write_lesson(
    dir: &Path,
    frames: &[LessonFrame],
    seconds: f64,
) -> Result<LessonFiles> {
    if frames.is_empty() {
        return Err(crate::Error::from(
            "no frames to write (pick a point first)",
        ));
    }
    std::fs::create_dir_all(dir).in_file(dir.display(), "")?;
    let size = frames[0].image.size;
    let mut pngs = Vec::with_capacity(frames.len());
    let mut text = String::from("# Lesson\n\n");
    let gif_path = dir.join("lesson.gif");
    let file = std::fs::File::create(&gif_path).in_file(gif_path.display(), "")?;
    let mut gif = GifEncoder::new_with_speed(std::io::BufWriter::new(file), 10);
    gif.set_repeat(Repeat::Infinite)
        .in_file(gif_path.display(), "")?;
    let delay = Delay::from_numer_denom_ms((seconds * 1000.0).round().max(20.0) as u32, 1);
    for (i, f) in frames.iter().enumerate() {
        let rgba = to_rgba(&f.image, size);
        let png = dir.join(format!("frame_{i:03}.png"));
        rgba.save_with_format(&png, image::ImageFormat::Png)
            .in_file(png.display(), "")?;
        gif.encode_frame(Frame::from_parts(rgba, 0, 0, delay))
            .in_file(gif_path.display(), "")?;
        text.push_str(&format!("## Frame {i:03}: {}\n\n", f.label));
        if let Some(l) = &f.lesson {
            text.push_str(&format!(
                "**{}**\n\n{}\n\n`{}`\n\n{}\n\n",
                l.title, l.text, l.equation, l.here
            ));
        }
        pngs.push(png);
    }
    drop(gif);
    let text_path = dir.join("lesson.md");
    std::fs::write(&text_path, text).in_file(text_path.display(), "")?;
    Ok(LessonFiles {
        frames: pngs,
        gif: gif_path,
        text: text_path,
    })
}

/// `img` as an RGBA image of `size` (padded with the transparent colour or cropped).
fn to_rgba(img: &ColorImage, size: [usize; 2]) -> RgbaImage {
    let mut out = RgbaImage::new(size[0] as u32, size[1] as u32);
    for y in 0..size[1].min(img.size[1]) {
        for x in 0..size[0].min(img.size[0]) {
            let c = img.pixels[y * img.size[0] + x];
            out.put_pixel(x as u32, y as u32, image::Rgba(c.to_array()));
        }
    }
    out
}

/// How many frames the tiles get to lay out a new step before its picture is taken.
const SETTLE_FRAMES: u32 = 3;

/// A capture in progress, advanced by the app once per frame ([`LessonCapture::advance`]).
pub(crate) struct LessonCapture {
    pub dir: PathBuf,
    /// Seconds per frame in the GIF.
    pub seconds: f64,
    /// The next step to show.
    next: usize,
    /// The step shown now, whose picture is taken when `settle` reaches 0.
    showing: Option<usize>,
    settle: u32,
    steps: usize,
    /// The step each frame shows.
    at: Vec<usize>,
    labels: Vec<(String, Option<Lesson>)>,
    /// Filled by the screenshot callbacks, which arrive a frame or two after the request.
    images: Arc<Mutex<Vec<Option<ColorImage>>>>,
}

/// What the app should do this frame.
pub(crate) enum CaptureAction {
    /// Show this step (and repaint).
    Show(usize),
    /// Take the picture of the subject's tile (the step shown is settled).
    Capture(usize),
    /// Waiting: for the layout, or for the screenshots to arrive.
    Wait,
    /// Every picture has arrived: write them.
    Write(Vec<LessonFrame>),
}

impl LessonCapture {
    /// A capture of `frames.len()` frames: the step each shows, with the stepper's label and
    /// lesson there, in order.
    pub fn new(dir: PathBuf, seconds: f64, frames: Vec<(usize, String, Option<Lesson>)>) -> Self {
        let steps = frames.len();
        let (at, labels) = frames.into_iter().map(|(i, l, s)| (i, (l, s))).unzip();
        LessonCapture {
            dir,
            seconds,
            next: 0,
            showing: None,
            settle: 0,
            steps,
            at,
            labels,
            images: Arc::new(Mutex::new(vec![None; steps])),
        }
    }

    /// Frames captured so far and in all.
    pub(crate) fn progress(&self) -> (usize, usize) {
        let done = self
            .images
            .lock()
            .map(|v| v.iter().filter(|i| i.is_some()).count())
            .unwrap_or(0);
        (done, self.steps)
    }

    /// One frame of the state machine.
    pub(crate) fn advance(&mut self) -> CaptureAction {
        if let Some(i) = self.showing {
            if self.settle > 0 {
                self.settle -= 1;
                return CaptureAction::Wait;
            }
            self.showing = None;
            return CaptureAction::Capture(i);
        }
        if self.next < self.steps {
            let i = self.next;
            self.next += 1;
            self.showing = Some(i);
            self.settle = SETTLE_FRAMES;
            return CaptureAction::Show(self.at[i]);
        }
        let Ok(images) = self.images.lock() else {
            return CaptureAction::Wait;
        };
        if images.iter().any(|i| i.is_none()) {
            return CaptureAction::Wait;
        }
        CaptureAction::Write(
            images
                .iter()
                .zip(&self.labels)
                .map(|(img, (label, lesson))| LessonFrame {
                    label: label.clone(),
                    lesson: lesson.clone(),
                    image: img.clone().unwrap_or_default(),
                })
                .collect(),
        )
    }

    /// The callback that stores step `i`'s picture (cropped to `crop`, in points).
    pub(crate) fn receiver(
        &self,
        i: usize,
        crop: Option<egui::Rect>,
        pixels_per_point: f32,
    ) -> impl FnOnce(Arc<ColorImage>) + Send + 'static {
        let images = self.images.clone();
        move |img| {
            let img = match crop {
                Some(r) => img.region(&r, Some(pixels_per_point)),
                None => (*img).clone(),
            };
            if let Ok(mut v) = images.lock()
                && let Some(slot) = v.get_mut(i)
            {
                *slot = Some(img);
            }
        }
    }
}
