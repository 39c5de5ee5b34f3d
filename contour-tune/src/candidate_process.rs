//! Candidates through FMUs in child processes: a plant FMU that hangs or crashes ends the
//! worker process it runs in, not the tuner. `ccc-tune` starts itself as a worker
//! (`--worker`, its own options otherwise) per evaluating thread; a worker loads the loop,
//! watches every FMU call (a call longer than the timeout ends the worker, as it ends a
//! `contour-cosim` run) and scores the candidates it is sent one by one. A candidate whose
//! worker ended scores as a run that cannot start and is recorded with the worker's last
//! words; the next candidate gets a new worker.
//!
//! The protocol is one line each way, numbers as the hexadecimal bits of their f64 (the
//! fitness comes back bit for bit): the worker's greeting `ready TS SAMPLES`, then per
//! candidate `F1 F2 F3 F4 F5` and the answer `FITNESS`. The worker writes them to the
//! standard output it set aside before loading any FMU, so what an FMU prints cannot
//! corrupt them.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::{Arc, Mutex};

use crate::fmu_objective::FmuObjective;
use crate::objective::PENALTY_MM;

/// The option that makes `ccc-tune` a worker.
pub const WORKER_FLAG: &str = "--worker";

/// How long a worker that stopped answering may take to end by itself.
const GRACE: std::time::Duration = std::time::Duration::from_secs(2);

/// How much of a worker's standard error is kept for the record of its end.
const KEPT_STDERR: usize = 4096;

/// What the first worker reports of the loop: the step and the samples of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Greeting {
    pub ts: f64,
    pub samples: usize,
}

/// A candidate whose worker ended: its factors and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub factors: Vec<f64>,
    pub reason: String,
}

/// The worker processes of a tuning run, one per evaluating thread at most.
pub struct Workers {
    program: PathBuf,
    args: Vec<String>,
    greeting: Greeting,
    idle: Mutex<Vec<Worker>>,
    failures: Mutex<Vec<Failure>>,
}

struct Worker {
    child: Child,
    /// The worker's temporary folder (its TMPDIR, TMP and TEMP): the FMUs it unpacks go
    /// there, and the folder goes when the worker does, however it ended (a worker that
    /// an FMU call hung ends at once, without cleaning up).
    _scratch: tempfile::TempDir,
    /// Closed to end the worker: it then frees its instances and unpacked FMUs.
    input: Option<ChildStdin>,
    output: BufReader<ChildStdout>,
    /// The tail of what the worker wrote to standard error since its current request
    /// (since its start, before the first).
    stderr: Arc<Mutex<Vec<u8>>>,
}

impl Workers {
    /// Starts the first worker (`program` with `args` and [`WORKER_FLAG`]) and reads its
    /// greeting; a worker that cannot load the loop ends with its message, which is the
    /// error.
    pub fn start(program: PathBuf, args: Vec<String>) -> Result<Workers, String> {
        let mut first = Worker::spawn(&program, &args)?;
        let greeting = match first.greeting() {
            Ok(greeting) => greeting,
            Err(e) => return Err(first.ended(&e)),
        };
        Ok(Workers {
            program,
            args,
            greeting,
            idle: Mutex::new(vec![first]),
            failures: Mutex::new(Vec::new()),
        })
    }

    /// The loop's step and run length, as the first worker found them.
    pub fn greeting(&self) -> Greeting {
        self.greeting
    }

    /// The fitness (mm) of these factors; a candidate whose worker ends (an FMU call that
    /// hangs past the timeout, a crash) scores as a run that cannot start and is recorded.
    pub fn evaluate(&self, factors: &[f64]) -> f64 {
        // An idle worker that died while it waited (killed from outside) is not this
        // candidate's fault: it is replaced, and so is a worker that failed to start, once.
        let taken = self
            .idle
            .lock()
            .ok()
            .and_then(|mut idle| idle.pop())
            .and_then(|mut w| w.is_alive().then_some(w));
        let worker = match taken {
            Some(worker) => Ok(worker),
            None => self.spawn().or_else(|_| self.spawn()),
        };
        let outcome = worker.and_then(|mut w| match w.score(factors) {
            Ok(fitness) => Ok((w, fitness)),
            Err(e) => Err(w.ended(&e)),
        });
        match outcome {
            Ok((worker, fitness)) => {
                if let Ok(mut idle) = self.idle.lock() {
                    idle.push(worker);
                }
                fitness
            }
            Err(reason) => {
                if let Ok(mut failures) = self.failures.lock() {
                    failures.push(Failure {
                        factors: factors.to_vec(),
                        reason,
                    });
                }
                2.0 * PENALTY_MM
            }
        }
    }

    /// A new worker that greets as the first did (every worker loads the same loop).
    fn spawn(&self) -> Result<Worker, String> {
        let mut worker = Worker::spawn(&self.program, &self.args)?;
        match worker.greeting() {
            Ok(g) if g == self.greeting => Ok(worker),
            Ok(g) => Err(worker.ended(&format!("a worker found another loop: {g:?}"))),
            Err(e) => Err(worker.ended(&e)),
        }
    }

    /// The candidates whose workers ended, in the order of their factors (the same list
    /// whatever the threads' timing).
    pub fn failures(&self) -> Vec<Failure> {
        let mut failures = self.failures.lock().map(|f| f.clone()).unwrap_or_default();
        failures.sort_by(|a, b| {
            a.factors
                .iter()
                .zip(&b.factors)
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        failures
    }
}

impl Worker {
    fn spawn(program: &PathBuf, args: &[String]) -> Result<Worker, String> {
        let scratch = tempfile::Builder::new()
            .prefix("ccc-tune-worker-")
            .tempdir()
            .map_err(|e| format!("cannot make a folder for a worker: {e}"))?;
        let mut child = Command::new(program)
            .args(args)
            .arg(WORKER_FLAG)
            .env("TMPDIR", scratch.path())
            .env("TMP", scratch.path())
            .env("TEMP", scratch.path())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start a worker ({}): {e}", program.display()))?;
        let (input, output, mut errors) =
            match (child.stdin.take(), child.stdout.take(), child.stderr.take()) {
                (Some(i), Some(o), Some(e)) => (i, o, e),
                _ => return Err("a worker without its pipes".into()),
            };
        // Drained all the time (an FMU may log a lot), the tail kept.
        let stderr = Arc::new(Mutex::new(Vec::new()));
        let kept = stderr.clone();
        std::thread::spawn(move || {
            let mut chunk = [0u8; 1024];
            while let Ok(n) = errors.read(&mut chunk) {
                if n == 0 {
                    break;
                }
                if let Ok(mut kept) = kept.lock() {
                    kept.extend_from_slice(&chunk[..n]);
                    let excess = kept.len().saturating_sub(KEPT_STDERR);
                    kept.drain(..excess);
                }
            }
        });
        Ok(Worker {
            child,
            _scratch: scratch,
            input: Some(input),
            output: BufReader::new(output),
            stderr,
        })
    }

    fn line(&mut self) -> Result<String, String> {
        let mut line = String::new();
        match self.output.read_line(&mut line) {
            Ok(0) => Err("the worker ended".into()),
            Ok(_) => Ok(line.trim_end().to_string()),
            Err(e) => Err(format!("cannot read the worker: {e}")),
        }
    }

    fn greeting(&mut self) -> Result<Greeting, String> {
        let line = self.line()?;
        let mut words = line.split(' ');
        match (words.next(), words.next(), words.next(), words.next()) {
            (Some("ready"), Some(ts), Some(samples), None) => Ok(Greeting {
                ts: from_hex(ts)?,
                samples: samples
                    .parse()
                    .map_err(|_| format!("a worker's greeting: {line:?}"))?,
            }),
            _ => Err(format!("a worker's greeting: {line:?}")),
        }
    }

    fn score(&mut self, factors: &[f64]) -> Result<f64, String> {
        if let Ok(mut kept) = self.stderr.lock() {
            kept.clear();
        }
        let request: Vec<String> = factors.iter().map(|&f| to_hex(f)).collect();
        let input = self.input.as_mut().ok_or("the worker's input is closed")?;
        writeln!(input, "{}", request.join(" "))
            .and_then(|()| input.flush())
            .map_err(|e| format!("cannot write to the worker: {e}"))?;
        from_hex(&self.line()?)
    }

    /// Ends the worker (if it still runs) and says why it ended: its last message on
    /// standard error, or its exit status.
    fn ended(mut self, what: &str) -> String {
        // A worker that closed its answers is on its way out, its last words on stderr
        // still to come: it gets a moment before it is killed.
        let status = self.finish();
        // The drain sees the pipe close once the worker is gone; give it a moment.
        for _ in 0..50 {
            if Arc::strong_count(&self.stderr) == 1 {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        let text = self
            .stderr
            .lock()
            .map(|b| String::from_utf8_lossy(&b).into_owned())
            .unwrap_or_default();
        let status = match status {
            Ok(status) => status.to_string(),
            Err(e) => e.to_string(),
        };
        // The worker's own last words (a timeout, a loop it cannot load) say it all;
        // otherwise how it ended, with the last thing it (or an FMU in it) printed.
        let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
        if let Some(own) = lines
            .iter()
            .rev()
            .find_map(|l| l.strip_prefix("ccc-tune: "))
        {
            return own.trim().to_string();
        }
        // A panic: where, and its message on the line after.
        if let Some(at) = lines.iter().position(|l| l.contains("panicked at")) {
            let message = lines.get(at + 1).map_or("", |l| l.trim());
            return format!("{what} ({status}): {} {message}", lines[at].trim());
        }
        match lines.last() {
            Some(last) => format!("{what} ({status}); it last wrote: {}", last.trim()),
            None => format!("{what} ({status})"),
        }
    }
}

impl Worker {
    /// Whether the worker still runs.
    fn is_alive(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }

    /// Closes the worker's input and waits a moment for it to end by itself (freeing its
    /// instances and the FMUs it unpacked) before it is killed; its exit status.
    fn finish(&mut self) -> std::io::Result<std::process::ExitStatus> {
        drop(self.input.take());
        let deadline = std::time::Instant::now() + GRACE;
        while matches!(self.child.try_wait(), Ok(None)) && std::time::Instant::now() < deadline {
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        let _ = self.child.kill();
        self.child.wait()
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

fn to_hex(value: f64) -> String {
    format!("{:016x}", value.to_bits())
}

fn from_hex(text: &str) -> Result<f64, String> {
    u64::from_str_radix(text, 16)
        .map(f64::from_bits)
        .map_err(|_| format!("not a number from a worker: {text:?}"))
}

/// A worker's side: greets with the loop's step and run length, then scores every
/// candidate line read from `input` until it ends.
pub fn serve(
    objective: &FmuObjective,
    input: impl BufRead,
    mut output: impl Write,
) -> Result<(), String> {
    let io = |e: std::io::Error| format!("the worker's pipe: {e}");
    let reference = objective.reference();
    writeln!(
        output,
        "ready {} {}",
        to_hex(reference.ts()),
        reference.simulator().samples()
    )
    .and_then(|()| output.flush())
    .map_err(io)?;
    for line in input.lines() {
        let line = line.map_err(io)?;
        let factors = line
            .split(' ')
            .map(from_hex)
            .collect::<Result<Vec<_>, _>>()?;
        writeln!(output, "{}", to_hex(objective.evaluate(&factors)))
            .and_then(|()| output.flush())
            .map_err(io)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_cross_the_pipe_bit_for_bit() {
        for v in [0.0, -0.0, 1.0 / 3.0, f64::MIN_POSITIVE, 1e300, 87.0] {
            assert_eq!(from_hex(&to_hex(v)).unwrap().to_bits(), v.to_bits());
        }
        assert!(from_hex("zz").is_err());
    }
}
