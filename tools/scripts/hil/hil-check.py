import sys, os; print(sorted(os.listdir(sys.argv[1])))
