//! A long run's CSV: millions of lines of numbers, formatted in blocks on two threads and
//! written in order by a third.

use std::io::Write;
use std::sync::mpsc;

/// Lines written per block of [`write`].
const LINES_PER_BLOCK: usize = 1 << 15;

/// Writes `count` lines, the k-th formatted by `line(text, k)`. With `threads` > 1 this
/// thread formats the even blocks and a second the odd ones while a third writes them in
/// order: formatting and the copy into the file's pages (as slow as the machine's memory
/// makes it) overlap. Each block's buffer goes back to its formatter to be filled again.
pub fn write(
    w: &mut (impl Write + Send),
    count: usize,
    threads: usize,
    line: impl Fn(&mut String, usize) + Sync,
) -> std::io::Result<()> {
    let blocks = count.div_ceil(LINES_PER_BLOCK);
    let block = |b: usize, text: &mut String| {
        text.clear();
        let lines = b * LINES_PER_BLOCK..((b + 1) * LINES_PER_BLOCK).min(count);
        lines.for_each(|k| line(text, k));
    };
    if threads < 2 {
        let mut text = String::new();
        for b in 0..blocks {
            block(b, &mut text);
            w.write_all(text.as_bytes())?;
        }
        return Ok(());
    }
    // Per parity: the formatted blocks to the writer, the written buffers back.
    let (even, even_written) = (mpsc::sync_channel::<String>(1), mpsc::channel::<String>());
    let (odd, odd_written) = (mpsc::sync_channel::<String>(1), mpsc::channel::<String>());
    let format =
        |parity: usize, to_write: mpsc::SyncSender<String>, written: mpsc::Receiver<String>| {
            for b in (parity..blocks).step_by(2) {
                let mut text = written.try_recv().unwrap_or_default();
                block(b, &mut text);
                if to_write.send(text).is_err() {
                    return; // the writer stopped on an error
                }
            }
        };
    std::thread::scope(|scope| {
        let (even_back, odd_back) = (even_written.0, odd_written.0);
        let (even_rx, odd_rx) = (even.1, odd.1);
        let writer = scope.spawn(move || {
            for b in 0..blocks {
                let (formatted, back) = if b % 2 == 0 {
                    (&even_rx, &even_back)
                } else {
                    (&odd_rx, &odd_back)
                };
                // A formatter that panicked ends the writer; the scope then raises it.
                let Ok(text) = formatted.recv() else {
                    return Ok(());
                };
                w.write_all(text.as_bytes())?;
                let _ = back.send(text);
            }
            Ok(())
        });
        let (odd_tx, odd_written_rx) = (odd.0, odd_written.1);
        scope.spawn(move || format(1, odd_tx, odd_written_rx));
        format(0, even.0, even_written.1);
        writer.join().expect("writing does not panic")
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fmt::Write as _;

    #[test]
    fn blocks_on_two_threads_write_the_lines_in_order() {
        let line = |text: &mut String, k: usize| {
            writeln!(text, "{k},{}", k as f64 / 7.0).unwrap();
        };
        for count in [
            0,
            1,
            LINES_PER_BLOCK,
            2 * LINES_PER_BLOCK + 1,
            5 * LINES_PER_BLOCK + 17,
        ] {
            let mut expected = String::new();
            (0..count).for_each(|k| line(&mut expected, k));
            for threads in [1, 2, 8] {
                let mut written = Vec::new();
                write(&mut written, count, threads, line).unwrap();
                assert!(
                    written == expected.as_bytes(),
                    "{count} lines, {threads} threads"
                );
            }
        }
    }

    /// A file that fails after `room` bytes.
    struct Full {
        room: usize,
    }

    impl Write for Full {
        fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
            if bytes.len() > self.room {
                return Err(std::io::Error::other("no space left"));
            }
            self.room -= bytes.len();
            Ok(bytes.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_failed_write_ends_the_formatters_and_is_returned() {
        let line = |text: &mut String, k: usize| writeln!(text, "{k}").unwrap();
        for threads in [1, 2] {
            let mut full = Full { room: 100_000 };
            let e = write(&mut full, 10 * LINES_PER_BLOCK, threads, line).unwrap_err();
            assert_eq!(e.to_string(), "no space left", "{threads} threads");
        }
    }
}
