"""What a person looks at: the rerun recording and blueprint, replay."""
