//! The session loop: a reader thread turns stdin into commands on a channel (raising a flag
//! the render polls before every pixel, so a command cancels the pass in flight), and the
//! loop applies every queued command (views coalesced: only the newest is applied), then
//! renders the next progressive pass and writes it as an IMAGE frame.

use std::io::{BufWriter, Read, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use serde_json::{Value, json};

use super::protocol::{self, Command, CommandError, Envelope, ImageHeader};
use super::schedule;
use super::state::{Effect, State};
use crate::denoise::Denoiser;
use crate::film::{Pass, PassSet};
use crate::render::{Progressive, RenderError, Sampling};

/// How the session was started.
#[derive(Clone, Debug, Default)]
pub struct SessionOptions {
    /// Worker threads (0: one per core).
    pub threads: usize,
    /// The Open Image Denoise library, for `settings.denoise`.
    pub oidn_lib: Option<std::path::PathBuf>,
}

/// What the reader thread hands the loop.
enum Incoming {
    Command(Result<Envelope, CommandError>),
    /// End of input: the add-on is gone or done.
    End,
    /// The framing is lost: the session cannot go on.
    Broken(String),
}

/// Grace the loop has to return after the end of input before the reader ends the process
/// (a BVH build in progress is not cancellable).
const EOF_GRACE: Duration = Duration::from_millis(200);

/// Frames out, each flushed as a whole; a failed write means the reader is gone.
struct Output<W: Write> {
    w: BufWriter<W>,
    gone: bool,
}

impl<W: Write> Output<W> {
    fn frame(&mut self, kind: u32, payload: &[u8]) {
        if self.gone {
            return;
        }
        let ok = protocol::write_frame(&mut self.w, kind, payload).and_then(|_| self.w.flush());
        self.gone = ok.is_err();
    }

    fn log(&mut self, level: u32, message: &str) {
        eprintln!("tesela session: {message}");
        self.frame(protocol::LOG, &protocol::log(level, message));
    }

    fn error(&mut self, command: Option<&str>, id: &Value, message: &str, fatal: bool) {
        eprintln!(
            "tesela session: error ({}): {message}",
            command.unwrap_or("frame")
        );
        self.frame(
            protocol::ERROR,
            &protocol::error(command, id, message, fatal),
        );
    }
}

/// An IMAGE frame's header and pixels.
type Picture = (ImageHeader, Vec<[f32; 4]>);

/// One progressive render of one generation.
struct Job {
    generation: u64,
    started: Instant,
    /// The pixel size of the next pass.
    divider: u32,
    /// The film at the viewport's pixel size, once the reduced passes are done.
    film: Option<Progressive>,
    done: bool,
}

impl Job {
    fn new(state: &State) -> Job {
        let s = &state.settings;
        let divider = state.view.as_ref().map_or(1, |v| {
            let [_, _, w, h] = v.border.unwrap_or([0, 0, v.width, v.height]);
            schedule::start_divider(w, h, s.start_resolution, s.pixel_size)
        });
        Job {
            generation: state.generation,
            started: Instant::now(),
            divider,
            film: None,
            done: state.loaded.is_none() || state.view.is_none(),
        }
    }

    /// Renders the next pass; the image to send, or `None` when the job is done.
    fn step(
        &mut self,
        state: &State,
        pool: &rayon::ThreadPool,
        threads: usize,
        cancel: &AtomicBool,
        denoiser: Option<&Denoiser>,
    ) -> Result<Option<Picture>, RenderError> {
        let (Some(loaded), Some(view)) = (&state.loaded, &state.view) else {
            self.done = true;
            return Ok(None);
        };
        let scene = &loaded.render;
        let pixel_size = state.settings.pixel_size.max(1);
        let target = state.settings.samples;
        let header =
            |d: u32, w: u32, h: u32, samples: u32, flags: u32, window: [u32; 4]| ImageHeader {
                generation: self.generation,
                view_width: view.width,
                view_height: view.height,
                window,
                pixel_size: d,
                data_width: w,
                data_height: h,
                samples,
                flags,
            };
        if self.divider > pixel_size {
            let d = self.divider;
            let (opts, window) = state
                .render_options(d, threads)
                .ok_or(RenderError::Cancelled)?;
            let mut film = Progressive::new(scene, &opts, Sampling::Sobol)?;
            film.round(scene, 1, pool, cancel)?;
            let img = film.image();
            self.divider = (d / 2).max(pixel_size);
            let flags = if target == 1 && self.divider == pixel_size && pixel_size == d {
                protocol::FLAG_FINAL
            } else {
                0
            };
            let h = header(d, img.width, img.height, 1, flags, window);
            return Ok(Some((h, img.pixels)));
        }
        let (mut opts, window) = state
            .render_options(pixel_size, threads)
            .ok_or(RenderError::Cancelled)?;
        if denoiser.is_some() {
            // The guides OIDN takes: the first surfaces' albedo and normal.
            opts.passes = PassSet::new([Pass::DenoisingAlbedo, Pass::DenoisingNormal]);
        }
        if self.film.is_none() {
            self.film = Some(Progressive::new(scene, &opts, Sampling::Sobol)?);
        }
        let film = self.film.as_mut().ok_or(RenderError::Cancelled)?;
        let Some(end) = schedule::next_round(film.samples(), target) else {
            self.done = true;
            return Ok(None);
        };
        film.round(scene, end, pool, cancel)?;
        let mut img = film.image();
        let last = target != 0 && end >= target;
        if last {
            self.done = true;
        }
        let mut flags = if last { protocol::FLAG_FINAL } else { 0 };
        // The film stays noisy and refines on; what is sent is denoised.
        if let Some(d) = denoiser
            && img.denoise(d, true).is_ok()
        {
            flags |= protocol::FLAG_DENOISED;
        }
        let h = header(pixel_size, img.width, img.height, end, flags, window);
        Ok(Some((h, img.pixels)))
    }
}

/// Runs a session on `input` and `output` until the input ends, `stop`, or the framing breaks.
/// Returns the exit status (0, or 2 for a broken framing).
pub fn run(
    opts: &SessionOptions,
    mut input: impl Read + Send + 'static,
    output: impl Write,
    signal: &'static AtomicBool,
) -> i32 {
    let interrupt = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    {
        let interrupt = interrupt.clone();
        std::thread::spawn(move || {
            loop {
                let msg = match protocol::read_frame(&mut input) {
                    Ok(Some((kind, payload))) => {
                        Incoming::Command(protocol::parse_command(kind, &payload))
                    }
                    Ok(None) => Incoming::End,
                    Err(e) => Incoming::Broken(e.to_string()),
                };
                let code = match msg {
                    Incoming::Command(_) => None,
                    Incoming::End => Some(0),
                    Incoming::Broken(_) => Some(2),
                };
                let sent = tx.send(msg).is_ok();
                interrupt.store(true, Ordering::SeqCst);
                if code.is_some() || !sent {
                    std::thread::sleep(EOF_GRACE);
                    std::process::exit(code.unwrap_or(0));
                }
            }
        });
    }
    // Signals end the session at once.
    std::thread::spawn(move || {
        while !signal.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(5));
        }
        std::process::exit(130);
    });
    let threads = if opts.threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        opts.threads
    };
    let mut out = Output {
        w: BufWriter::with_capacity(1 << 20, output),
        gone: false,
    };
    out.frame(protocol::HELLO, &protocol::hello(threads));
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(p) => p,
        Err(e) => {
            out.error(
                None,
                &Value::Null,
                &format!("cannot start worker threads: {e}"),
                true,
            );
            return 2;
        }
    };
    let mut state = State::default();
    // Loaded the first time `denoise` is asked for; `Err`: it cannot be (said once).
    let mut denoiser: Option<Result<Denoiser, String>> = None;
    let mut job: Option<Job> = None;
    let mut paused = false;
    loop {
        if out.gone {
            return 0;
        }
        interrupt.store(false, Ordering::SeqCst);
        let idle = paused || job.as_ref().is_none_or(|j| j.done);
        let mut batch = Vec::new();
        if idle {
            match rx.recv() {
                Ok(m) => batch.push(m),
                Err(_) => return 0,
            }
        }
        batch.extend(rx.try_iter());
        let is_view = |m: &Incoming| matches!(m, Incoming::Command(Ok(e)) if matches!(e.command, Command::View(_)));
        let newest_view = batch.iter().rposition(is_view);
        let mut restart = false;
        for (i, m) in batch.into_iter().enumerate() {
            let env = match m {
                Incoming::End => return 0,
                Incoming::Broken(e) => {
                    out.error(None, &Value::Null, &e, true);
                    return 2;
                }
                Incoming::Command(Err(e)) => {
                    out.error(e.cmd.as_deref(), &e.id, &e.message, false);
                    continue;
                }
                Incoming::Command(Ok(env)) => env,
            };
            if matches!(env.command, Command::View(_)) && Some(i) != newest_view {
                // A newer view replaces this one before anything was rendered of it.
                state.generation += 1;
                continue;
            }
            if !env.unknown.is_empty() {
                out.log(
                    protocol::LOG_WARNING,
                    &format!(
                        "{}: unknown fields ignored: {}",
                        env.cmd,
                        env.unknown.join(", ")
                    ),
                );
            }
            match state.apply(env.command) {
                Ok((effect, warnings)) => {
                    for w in warnings {
                        out.log(protocol::LOG_WARNING, &w);
                    }
                    match effect {
                        Effect::Restart => restart = true,
                        Effect::Pause => paused = true,
                        Effect::Resume => paused = false,
                        Effect::Stop => return 0,
                    }
                }
                Err(message) => out.error(Some(&env.cmd), &env.id, &message, false),
            }
        }
        if restart || job.is_none() {
            job = Some(Job::new(&state));
        }
        if state.settings.denoise && denoiser.is_none() {
            let d = Denoiser::load(opts.oidn_lib.as_deref(), threads).map_err(|e| e.to_string());
            match &d {
                Ok(d) => out.log(
                    protocol::LOG_INFO,
                    &format!("denoising with {}", d.describe()),
                ),
                Err(e) => out.log(
                    protocol::LOG_WARNING,
                    &format!("{e}; the viewport is not denoised"),
                ),
            }
            denoiser = Some(d);
        }
        let use_denoiser = match &denoiser {
            Some(Ok(d)) if state.settings.denoise => Some(d),
            _ => None,
        };
        if paused {
            stats(&mut out, &state, job.as_ref(), "paused");
            continue;
        }
        let Some(j) = job.as_mut() else { continue };
        if j.done {
            continue;
        }
        match j.step(&state, &pool, threads, &interrupt, use_denoiser) {
            Ok(Some((header, pixels))) => {
                out.frame(protocol::IMAGE, &protocol::image(&header, &pixels));
                let s = if j.done { "done" } else { "rendering" };
                stats(&mut out, &state, job.as_ref(), s);
                if let Some(j) = job.as_mut()
                    && header.flags & protocol::FLAG_FINAL != 0
                {
                    j.done = true;
                }
            }
            Ok(None) => {}
            Err(RenderError::Cancelled) => {
                let msg = format!("generation {}: pass cancelled by a command", j.generation);
                out.frame(protocol::LOG, &protocol::log(protocol::LOG_DEBUG, &msg));
            }
            Err(RenderError::Invalid(m)) => {
                out.error(Some("render"), &Value::Null, &m, false);
                j.done = true;
            }
        }
    }
}

/// A STATS frame for the job as it stands.
fn stats<W: Write>(out: &mut Output<W>, state: &State, job: Option<&Job>, what: &str) {
    let seconds = job.map_or(0.0, |j| j.started.elapsed().as_secs_f64());
    let film = job.and_then(|j| j.film.as_ref());
    let samples = film.map_or(0, |f| f.samples());
    let st = film.map(|f| f.stats(seconds));
    let triangles = state
        .loaded
        .as_ref()
        .map_or(0, |l| l.render.triangle_count());
    let s = json!({
        "generation": state.generation,
        "samples": samples,
        "target_samples": state.settings.samples,
        "pixel_size": job.map_or(1, |j| j.divider),
        "seconds": seconds,
        "samples_per_second": st.as_ref().map_or(0.0, |s| s.samples_per_second),
        "rays_per_second": st.as_ref().map_or(0.0, |s| s.rays_per_second),
        "triangles": triangles,
        "state": what,
    });
    out.frame(protocol::STATS, s.to_string().as_bytes());
}
