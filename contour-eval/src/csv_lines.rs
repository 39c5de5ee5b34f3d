//! A long run's CSV: millions of lines of numbers, formatted in blocks, two at a time on
//! two threads, and written in order.

use std::io::Write;

/// Lines written per block of [`write`].
const LINES_PER_BLOCK: usize = 1 << 15;

/// Writes `count` lines, the k-th formatted by `line(text, k)`: with `threads` > 1 two
/// blocks of lines at a time, the second formatted by a thread of its own while this one
/// formats the first (a long run's CSV is millions of numbers to print).
pub fn write(
    w: &mut impl Write,
    count: usize,
    threads: usize,
    line: impl Fn(&mut String, usize) + Sync,
) -> std::io::Result<()> {
    let block = |lines: std::ops::Range<usize>, text: &mut String| {
        text.clear();
        lines.for_each(|k| line(text, k));
    };
    let (mut first, mut second) = (String::new(), String::new());
    for start in (0..count).step_by(2 * LINES_PER_BLOCK) {
        let middle = (start + LINES_PER_BLOCK).min(count);
        let end = (middle + LINES_PER_BLOCK).min(count);
        if threads > 1 {
            std::thread::scope(|scope| {
                let later = scope.spawn(|| block(middle..end, &mut second));
                block(start..middle, &mut first);
                later.join().expect("formatting does not panic");
            });
        } else {
            block(start..middle, &mut first);
            block(middle..end, &mut second);
        }
        w.write_all(first.as_bytes())?;
        w.write_all(second.as_bytes())?;
    }
    Ok(())
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
}
