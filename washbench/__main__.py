from washbench.cli import main

raise SystemExit(main())
