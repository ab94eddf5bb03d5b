"""What a person looks at: the rerun recording and blueprint, replay."""

import os

# The rerun SDK's own log lines (e.g. its file sink's errors on a full disk) are off unless RUST_LOG asks for
# them: washbench reports a failed recording itself, as one line (washbench.review.rerun_log.close_recording).
os.environ.setdefault("RUST_LOG", "off")
