//! A frame's GPU time from timestamp queries, where the adapter has them
//! (`wgpu::Features::TIMESTAMP_QUERY`; [`crate::Gpu`] asks for it when offered).
//!
//! The frame's first pass writes a timestamp at its start, the composition pass one at its end;
//! both are resolved into a small buffer and copied into a read-back buffer with the frame. The
//! read-back is mapped after the submission and read when it is ready — usually by the next
//! frame, never waited for — so a reading is that of an earlier frame, and each is handed out
//! once (a controller must not count one measurement twice). While a reading is in flight,
//! frames are not timed (one buffer, never written while mapped).
//!
//! Threading: the render thread's, like the renderer; the map callback only sets a flag. Never
//! panics: a failed map or an implausible reading is dropped.

use std::sync::{Arc, Mutex};

/// Where the one reading is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// The buffers are free: the next frame may be timed.
    Idle,
    /// This frame writes timestamps; not submitted yet.
    Encoded,
    /// Submitted, mapping requested.
    Mapping,
    /// Mapped: ready to read.
    Mapped,
    /// The map failed: unmap and start again.
    Failed,
}

pub(crate) struct GpuTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    state: Arc<Mutex<State>>,
    /// Nanoseconds per timestamp tick.
    period_ns: f64,
    /// A reading not yet taken.
    fresh_s: Option<f64>,
}

const BYTES: u64 = 2 * wgpu::QUERY_SIZE as u64;

impl GpuTimer {
    /// `None` where the device has no timestamp queries.
    pub(crate) fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Self> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("frame time"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: BYTES,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            set,
            resolve: buffer(
                "frame time resolve",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            readback: buffer(
                "frame time read-back",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
            state: Arc::new(Mutex::new(State::Idle)),
            period_ns: f64::from(queue.get_timestamp_period()),
            fresh_s: None,
        })
    }

    fn state(&self) -> State {
        self.state.lock().map_or(State::Failed, |s| *s)
    }

    fn set_state(&self, state: State) {
        if let Ok(mut s) = self.state.lock() {
            *s = state;
        }
    }

    /// Whether this frame can be timed; if so, the caller writes [`Self::writes`] into its first
    /// and last passes and calls [`Self::resolve`] before finishing the encoder.
    pub(crate) fn start_frame(&mut self) -> bool {
        self.collect();
        if self.state() == State::Idle {
            self.set_state(State::Encoded);
            true
        } else {
            false
        }
    }

    /// The timestamp writes of a pass that begins (`begin`) and/or ends (`end`) the frame.
    pub(crate) fn writes(&self, begin: bool, end: bool) -> wgpu::RenderPassTimestampWrites<'_> {
        wgpu::RenderPassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: begin.then_some(0),
            end_of_pass_write_index: end.then_some(1),
        }
    }

    /// Resolves the frame's two timestamps into the read-back buffer.
    pub(crate) fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..2, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, BYTES);
    }

    /// After the frame's submission: asks for the reading.
    pub(crate) fn submitted(&self) {
        if self.state() != State::Encoded {
            return;
        }
        self.set_state(State::Mapping);
        let state = Arc::clone(&self.state);
        self.readback.map_async(wgpu::MapMode::Read, .., move |r| {
            if let Ok(mut s) = state.lock() {
                *s = if r.is_ok() { State::Mapped } else { State::Failed };
            }
        });
    }

    /// A frame whose timestamps were encoded but not submitted (it failed): free the buffers.
    pub(crate) fn abandon(&self) {
        if self.state() == State::Encoded {
            self.set_state(State::Idle);
        }
    }

    /// Reads a finished reading (without waiting) and frees the buffers.
    fn collect(&mut self) {
        match self.state() {
            State::Mapped => {
                if let Ok(view) = self.readback.get_mapped_range(..) {
                    let ticks: [u64; 2] = bytemuck::pod_read_unaligned(&view[..BYTES as usize]);
                    let [start, end] = ticks;
                    // A reading that runs backwards or past ten seconds is no frame's.
                    let s = end.checked_sub(start).map(|t| t as f64 * self.period_ns * 1e-9);
                    if let Some(s) = s.filter(|s| *s > 0.0 && *s < 10.0) {
                        self.fresh_s = Some(s);
                    }
                }
                self.readback.unmap();
                self.set_state(State::Idle);
            }
            State::Failed => {
                self.readback.unmap();
                self.set_state(State::Idle);
            }
            State::Idle | State::Encoded | State::Mapping => {}
        }
    }

    /// The GPU time of a frame read since the last call, seconds (polling the device for it
    /// first, without waiting); `None` when no new reading has arrived.
    pub(crate) fn take_s(&mut self, device: &wgpu::Device) -> Option<f64> {
        let _ = device.poll(wgpu::PollType::Poll);
        self.collect();
        self.fresh_s.take()
    }
}
